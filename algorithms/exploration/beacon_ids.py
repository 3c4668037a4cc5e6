"""Beacon names as in Nagavarapu et al. section 3: robot R1 names its beacons a1, a2, a3, ...,
robot R2 b1, b2, ..., and so on.

The paper stops at the alphabet. Beyond 26 robots the letters continue in bijective
base 26, like spreadsheet columns: R27 is ``aa``, R28 ``ab``, ..., R52 ``az``, R53 ``ba``.
A name is letters then digits, so it can always be split back unambiguously.
"""

from __future__ import annotations

import functools
import re

_NAME = re.compile(r"([a-z]+)([1-9][0-9]*)")


@functools.cache  # a robot names every beacon it drops with them
def robot_letters(index: int) -> str:
    """Letters of the robot with 0-based ``index`` (0 -> ``a``, 25 -> ``z``, 26 -> ``aa``)."""
    if index < 0:
        raise ValueError(f"robot index must be >= 0, got {index}")
    letters = ""
    n = index + 1
    while n:
        n, rem = divmod(n - 1, 26)
        letters = chr(ord("a") + rem) + letters
    return letters


def beacon_id(index: int, sequence: int) -> str:
    """The ``sequence``-th (1-based) beacon of robot ``index`` (0-based), e.g. ``(1, 3) -> b3``."""
    if sequence < 1:
        raise ValueError(f"beacon sequence numbers start at 1, got {sequence}")
    return f"{robot_letters(index)}{sequence}"


def parse_beacon_id(name: str) -> tuple[int, int]:
    """Inverse of :func:`beacon_id`: ``(robot index, sequence)``."""
    match = _NAME.fullmatch(name)
    if match is None:
        raise ValueError(f"not a beacon id: {name!r}")
    letters, digits = match.groups()
    n = 0
    for ch in letters:
        n = n * 26 + (ord(ch) - ord("a") + 1)
    return n - 1, int(digits)

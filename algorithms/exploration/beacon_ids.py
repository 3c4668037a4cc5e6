"""Beacon names as in Nagavarapu et al. section 3: robot R1 names its beacons a1, a2, a3, ...,
robot R2 b1, b2, ..., and so on.

The paper stops at the alphabet. Beyond 26 robots the letters continue in bijective
base 26, like spreadsheet columns: R27 is ``aa``, R28 ``ab``, ..., R52 ``az``, R53 ``ba``.
A name is letters then digits, so no two robots' beacons share a name.
"""

from __future__ import annotations

import functools


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


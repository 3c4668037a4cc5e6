"""Numeric options checked as they are parsed: one home for every subcommand's ranges.

``parser.add_argument("--max-time", action=number(above=0), ...)`` converts the text
(argparse's own error if it is not a number at all) and refuses, in one line naming
the option (:class:`~mjswarm.errors.MjswarmError`), a value that is not finite or lies
outside its range: before any work, before any file is opened. ``most`` is a cap, given
with ``why`` (what the cap protects). :func:`check_number` is the same check for values
that come from elsewhere (lists, files).
"""

from __future__ import annotations

import argparse
import math
from functools import partial

from mjswarm.errors import MjswarmError


def check_number(flag: str, value: float, *, whole: bool = False, least: float | None = None,
                 above: float | None = None, most: float | None = None,
                 why: str = "") -> None:
    """Refuse, naming ``flag``, a ``value`` that is not finite, is below ``least`` or not
    above ``above``, or is over the cap ``most`` (``why``: the reason for the cap)."""
    kind = "whole number" if whole else "finite number"
    bound = (f" >= {least:g}" if least is not None else
             f" > {above:g}" if above is not None else "")
    if not (math.isfinite(value) and (least is None or value >= least)
            and (above is None or value > above)):
        raise MjswarmError(f"{flag} must be a {kind}{bound}, got {value:g}")
    if most is not None and value > most:
        raise MjswarmError(f"{flag} must be at most {most:g}" + (f" ({why})" if why else "")
                           + f", got {value:g}")


class _Checked(argparse.Action):
    """Stores one value of type ``kind`` after :func:`check_number` on it."""

    def __init__(self, option_strings, dest, *, kind: type, limits: dict, **kwargs) -> None:
        super().__init__(option_strings, dest, type=kind, **kwargs)
        self.limits = limits

    def __call__(self, parser, namespace, value, option_string=None) -> None:
        check_number(option_string or self.metavar or self.dest, value,
                     whole=self.type is int, **self.limits)
        setattr(namespace, self.dest, value)


def number(*, least: float | None = None, above: float | None = None,
           most: float | None = None, why: str = "") -> partial:
    """The ``action`` of a float option: finite, in range (see :func:`check_number`)."""
    return partial(_Checked, kind=float,
                   limits={"least": least, "above": above, "most": most, "why": why})


def whole(*, least: int | None = 1, most: int | None = None, why: str = "") -> partial:
    """The ``action`` of a whole-number option (default: at least 1)."""
    return partial(_Checked, kind=int,
                   limits={"least": least, "above": None, "most": most, "why": why})

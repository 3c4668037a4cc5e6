"""A griffe extension for the API reference: mjswarm's docstrings cross-reference with
reStructuredText roles (``:class:`~algorithms.robot.Observation```), which Markdown does
not know. Each role becomes inline code of the name it shows (``Observation``; the whole
path without ``~``) before mkdocstrings renders the docstring."""

from __future__ import annotations

import re

import griffe

ROLE = re.compile(r":(?:py:)?(?:class|mod|func|meth|attr|data|obj|exc|const):`(~?)([^`]+)`")


def plain(match: re.Match) -> str:
    short, target = match.group(1), match.group(2)
    return f"`{target.rsplit('.', 1)[-1] if short else target}`"


class SphinxRoles(griffe.Extension):
    def on_object(self, *, obj: griffe.Object, **kwargs) -> None:
        if obj.docstring is not None:
            obj.docstring.value = ROLE.sub(plain, obj.docstring.value)

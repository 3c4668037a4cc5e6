"""Shared ``--json PATH|-`` handling for the subcommands."""

from __future__ import annotations

import json
from pathlib import Path

from mjswarm.errors import MjswarmError


def write_json(data, target: str | None) -> bool:
    """Write ``data`` as JSON to ``target``: ``-`` is stdout, a path a file, None nothing.

    Returns True when it went to stdout (the caller then prints nothing else there).
    """
    if not target:
        return False
    text = json.dumps(data, indent=2)
    if target == "-":
        print(text)
        return True
    try:
        Path(target).write_text(text + "\n", encoding="utf-8")
    except OSError as exc:
        raise MjswarmError(f"cannot write {target}: {exc.strerror}") from None
    return False

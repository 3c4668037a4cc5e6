"""Output files of the subcommands: never lose what the user already has (issue 18).

* :func:`check_writable` runs before any simulation: a target whose directory is
  missing or read-only, or that is a directory, fails at once in one line, not after a
  long run.
* :func:`atomic_output` hands the writer a temporary file in the target's directory and
  moves it onto the target (``os.replace``, atomic on one file system) only when the
  writer is done: the run completed, did not complete, or was interrupted (the partial
  file is kept under the requested name, and :data:`interrupted_outputs` lists it so the
  CLI can say so). If the run is rejected or fails, the temporary file is removed and an
  existing file at the target is left byte for byte as it was.
* :func:`write_json` writes ``--json PATH|-`` that way.
"""

from __future__ import annotations

import json
import os
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from mjswarm.errors import MjswarmError

#: Targets that hold a partial result because the run was interrupted (for the message).
interrupted_outputs: list[str] = []


def check_writable(target: str | os.PathLike | None, what: str) -> None:
    """Fail now (one line) if ``target`` could not be written later; ``-`` and None pass."""
    if target is None or os.fspath(target) == "-":
        return
    path = Path(target)
    if path.is_dir():
        raise MjswarmError(f"cannot write {what} {path}: it is a directory")
    folder = path.parent
    if not folder.is_dir():
        raise MjswarmError(f"cannot write {what} {path}: directory {folder} does not exist")
    if not os.access(folder, os.W_OK | os.X_OK):
        raise MjswarmError(f"cannot write {what} {path}: directory {folder} is not writable")
    if path.exists() and not os.access(path, os.W_OK):
        raise MjswarmError(f"cannot write {what} {path}: the file is read-only")


@contextmanager
def atomic_output(target: str | os.PathLike, what: str) -> Iterator[Path]:
    """Yield a temporary path beside ``target``; move it onto ``target`` when the block
    ends normally or by KeyboardInterrupt, delete it on any other exception."""
    path = Path(target)
    check_writable(path, what)
    fd, temp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".part", dir=path.parent)
    os.close(fd)
    temp = Path(temp)
    try:
        yield temp
    except KeyboardInterrupt:
        _finish(temp, path)
        interrupted_outputs.append(str(path))
        raise
    except BaseException:
        temp.unlink(missing_ok=True)
        raise
    _finish(temp, path)


def _finish(temp: Path, path: Path) -> None:
    if temp.exists() and temp.stat().st_size > 0:
        os.replace(temp, path)
    else:
        temp.unlink(missing_ok=True)


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
        with atomic_output(target, "JSON") as temp:
            temp.write_text(text + "\n", encoding="utf-8")
    except OSError as exc:
        raise MjswarmError(f"cannot write {target}: {exc.strerror}") from None
    return False

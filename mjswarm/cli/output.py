"""Output files of the subcommands: never lose what the user already has.

* :func:`check_writable` runs before any simulation: a target whose directory is
  missing or read-only, or that is a directory, fails at once in one line, not after a
  long run; :func:`check_directory` does the same for an output directory.
  :func:`check_outputs` also refuses two outputs on one file and a file name whose
  extension is not the format written.
* :func:`atomic_output` hands the writer a temporary file and, when the writer is done,
  puts it in place according to what the target is:

  - a regular file, new or existing (through any symlinks: the link stays a link and the
    file it points to is written): the temporary file sits beside the file it replaces
    and is moved onto it (``os.replace``, atomic on one file system) with the mode a
    plain ``open()`` would give a new file, or the existing file's mode;
  - anything else that exists (a device such as ``/dev/null``, a FIFO, ``/dev/fd/N`` from
    a shell's ``>(...)``): the temporary file sits in the system's temporary directory
    and its bytes are written into the target, which is opened as a plain ``open()``
    would; nothing is renamed onto it.

  If the run is rejected or fails, the temporary file is removed and the target is left
  byte for byte as it was. If the run is interrupted (Ctrl-C) the partial output is kept:
  under the requested name when nothing was there, else beside the user's earlier file
  under :func:`partial_name` (the earlier file is left as it was); a special file gets
  the partial bytes. A partial with nothing to review in it (see :func:`drop_if_useless`)
  is not kept. :data:`interrupted_outputs` says where each one went, for the CLI's
  message.
* :func:`write_json` writes ``--json PATH|-`` that way.
"""

from __future__ import annotations

import json
import os
import shutil
import stat
import tempfile
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path

from mjswarm.errors import MjswarmError

#: Partial outputs of an interrupted run: requested target -> where the partial went
#: (None: nowhere, it held nothing).
interrupted_outputs: dict[str, str | None] = {}


def _stat(path: Path) -> os.stat_result | None:
    """The target's status through symlinks; None if there is nothing there (yet)."""
    try:
        return path.stat()
    except (FileNotFoundError, NotADirectoryError):
        return None


def _special(path: Path) -> bool:
    """Whether ``path`` exists and is not a regular file (a device, FIFO, socket, pipe)."""
    st = _stat(path)
    return st is not None and not stat.S_ISREG(st.st_mode) and not stat.S_ISDIR(st.st_mode)


def check_writable(target: str | os.PathLike | None, what: str) -> None:
    """Fail now (one line) if ``target`` could not be written later; ``-`` and None pass."""
    if target is None or os.fspath(target) == "-":
        return
    path = Path(target)
    if path.is_dir():
        raise MjswarmError(f"cannot write {what} {path}: it is a directory")
    if _special(path):
        if not os.access(path, os.W_OK):
            raise MjswarmError(f"cannot write {what} {path}: permission denied")
        return
    real = Path(os.path.realpath(path))
    folder = real.parent
    if not folder.is_dir():
        raise MjswarmError(f"cannot write {what} {path}: directory {folder} does not exist")
    if not os.access(folder, os.W_OK | os.X_OK):
        raise MjswarmError(f"cannot write {what} {path}: directory {folder} is not writable")
    if real.exists() and not os.access(real, os.W_OK):
        raise MjswarmError(f"cannot write {what} {path}: the file is read-only")


def check_directory(target: str | os.PathLike | None, what: str) -> None:
    """Fail now (one line) if the output directory ``target`` could not be made or written:
    it must be a directory, or a new one in an existing, writable directory (never a
    whole missing tree, as :func:`check_writable` refuses for files). None passes."""
    if target is None:
        return
    path = Path(target)
    if path.exists() and not path.is_dir():
        raise MjswarmError(f"cannot write {what} into {path}: it is not a directory")
    folder = path if path.is_dir() else Path(os.path.realpath(path)).parent
    if not folder.is_dir():
        raise MjswarmError(f"cannot write {what} into {path}: directory {folder} does not "
                           "exist")
    if not os.access(folder, os.W_OK | os.X_OK):
        raise MjswarmError(f"cannot write {what} into {path}: directory {folder} is not "
                           "writable")


def check_outputs(outputs: dict[str, str | None], suffixes: dict[str, str]) -> None:
    """Refuse, in one line, output options that would lose data or mislead.

    ``outputs`` maps an option (``--record``) to its target (None: not given, ``-``:
    stdout); ``suffixes`` maps an option to the extension its format needs (``.rrd``).
    Two options naming one file (the same path, or two names of one file) would
    overwrite each other; a special file (``/dev/null``, a FIFO) may take one output."""
    for flag, suffix in suffixes.items():
        target = outputs.get(flag)
        if target and target != "-" and not _special(Path(target)) \
                and Path(target).suffix.lower() != suffix:
            raise MjswarmError(f"{flag} writes {suffix} files: give a FILE{suffix}, "
                               f"got {target}")
    seen: dict[str, str] = {}
    for flag, target in outputs.items():
        if not target or target == "-":
            continue
        key = os.path.realpath(target)
        if key in seen:
            raise MjswarmError(f"{seen[key]} and {flag} name the same file {target}: "
                               "give each output its own file")
        seen[key] = flag


def partial_name(path: Path) -> Path:
    """Where an interrupted run's partial output goes when ``path`` holds an earlier
    output: ``NAME.partial.EXT`` beside it, or ``NAME.partial-2.EXT``, ... if taken."""
    n = 1
    while True:
        tag = "partial" if n == 1 else f"partial-{n}"
        candidate = path.with_name(f"{path.stem}.{tag}{path.suffix}")
        if not os.path.lexists(candidate):
            return candidate
        n += 1


def _new_file_mode() -> int:
    """The mode ``open(path, "w")`` gives a new file: 0666 less the process's umask."""
    mask = os.umask(0)
    os.umask(mask)
    return 0o666 & ~mask


@contextmanager
def atomic_output(target: str | os.PathLike, what: str,
                  partial: bool = False) -> Iterator[Path]:
    """Yield a temporary path for the writer; put its contents at ``target`` when the
    block ends normally or by KeyboardInterrupt (see the module docstring), delete it on
    any other exception. ``partial``: what is written is an interrupted run's, even if
    the block ends normally."""
    path = Path(target)
    check_writable(path, what)
    special = _special(path)
    final = path if special else Path(os.path.realpath(path))
    fd, temp = tempfile.mkstemp(prefix=f".{final.name}.", suffix=".part",
                                dir=None if special else final.parent)
    os.close(fd)
    temp = Path(temp)
    try:
        yield temp
    except KeyboardInterrupt:
        _finish(temp, final, special, interrupted=True, shown=str(path))
        raise
    except BaseException:
        temp.unlink(missing_ok=True)
        raise
    _finish(temp, final, special, interrupted=partial, shown=str(path))


def _finish(temp: Path, final: Path, special: bool, interrupted: bool, shown: str) -> None:
    """Put the writer's output in place (an empty one is dropped: nothing was written)."""
    if not (temp.exists() and temp.stat().st_size > 0):
        temp.unlink(missing_ok=True)
        if interrupted:
            interrupted_outputs[shown] = None
        return
    if special:
        try:
            with open(temp, "rb") as source, open(final, "wb") as sink:
                shutil.copyfileobj(source, sink)
        finally:
            temp.unlink(missing_ok=True)
        if interrupted:
            interrupted_outputs[shown] = shown
        return
    earlier = _stat(final)
    if interrupted and earlier is not None and earlier.st_size > 0:
        keep = partial_name(final)
        os.chmod(temp, stat.S_IMODE(earlier.st_mode))
        os.replace(temp, keep)
        interrupted_outputs[shown] = str(keep)
        return
    os.chmod(temp, _new_file_mode() if earlier is None else stat.S_IMODE(earlier.st_mode))
    os.replace(temp, final)
    if interrupted:
        interrupted_outputs[shown] = shown


def drop_if_useless(temp: Path, useful: Callable[[], bool]):
    """An exit callback for an :class:`~contextlib.ExitStack`, pushed between
    :func:`atomic_output` and the writer of ``temp``: when the block ends by Ctrl-C and
    ``useful()`` is false (say, a recording that holds no pose yet), ``temp`` is emptied,
    so that no partial is kept and the CLI says so."""

    def exit_callback(kind, value, traceback) -> bool:
        if kind is not None and issubclass(kind, KeyboardInterrupt) and not useful():
            temp.write_bytes(b"")
        return False

    return exit_callback


def write_json(data, target: str | None, partial: bool = False) -> bool:
    """Write ``data`` as JSON to ``target``: ``-`` is stdout, a path a file, None nothing;
    ``partial``: an interrupted run's result (kept as :func:`atomic_output` keeps one).

    Returns True when it went to stdout (the caller then prints nothing else there).
    """
    if not target:
        return False
    text = json.dumps(data, indent=2)
    if target == "-":
        print(text)
        return True
    try:
        with atomic_output(target, "JSON", partial) as temp:
            temp.write_text(text + "\n", encoding="utf-8")
    except OSError as exc:
        raise MjswarmError(f"cannot write {target}: {exc.strerror}") from None
    return False

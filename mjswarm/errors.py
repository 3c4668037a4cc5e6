"""The one exception type users see as a single clear line.

Anything the user can get wrong (a missing model file, a malformed arena spec,
an impossible parameter) raises :class:`MjswarmError` with a message that names
the problem; the CLI prints ``mjswarm: error: <message>`` and exits with status 2,
never a traceback.
"""


class MjswarmError(Exception):
    """A user-facing error: bad input, bad file, impossible parameters."""


def one_line(exc: BaseException, limit: int = 240) -> str:
    """An exception's message folded onto one line (for third-party multi-line errors)."""
    text = " ".join(str(exc).split()) or type(exc).__name__
    return text if len(text) <= limit else text[: limit - 3] + "..."


class RunInterrupted(KeyboardInterrupt):
    """Ctrl-C during a run: still a :class:`KeyboardInterrupt`, carrying what the run had
    measured so far (``result``, with ``ended_because == "interrupted"``) so that the CLI
    can write it (``--json``) and summarise it before it exits."""

    def __init__(self, result) -> None:
        super().__init__("interrupted")
        self.result = result

"""``--record`` and ``--video`` of the open-floor experiments as loop functions.

An experiment never knows what records or films it (it imports nothing from
:mod:`mjswarm.outputs`): the CLI makes the recording and the video here and hands them
in as loop functions; the experiment's events reach the recording through
:meth:`mjswarm.worlds.loop.Loop.event`, and its marks, links and roles reach the video
through :meth:`mjswarm.worlds.loop.LoopFunctions.scene`.
"""

from __future__ import annotations

from collections.abc import Sequence
from contextlib import ExitStack

from typing import TYPE_CHECKING

from mjswarm.cli.output import atomic_output, drop_if_useless

if TYPE_CHECKING:
    from mjswarm.worlds.loop import LoopFunctions


def watchers(outputs: ExitStack, args, *, robots: int, bounds_m: Sequence[float], name: str,
             title: str, speedup: float) -> list[LoopFunctions]:
    """The loop functions for ``args.record`` (a rerun recording of ``robots`` robots with
    radios, no sensors, framed on ``bounds_m``) and ``args.video``; all are finished, in
    the right order, when ``outputs`` closes."""
    from mjswarm.outputs.recording import Recorder, Recording
    from mjswarm.outputs.video import Video, filming

    functions: list[LoopFunctions] = []
    video = recorder = None
    if args.video:
        video = Video(outputs.enter_context(atomic_output(args.video, "video")), bounds_m,
                      speedup, title=title)
    if args.record:
        temp = outputs.enter_context(atomic_output(args.record, "recording"))
        recorder = Recorder(temp, None, robots, radio=True, sensors=False, bounds_m=bounds_m,
                            name=name, video=video is not None)
        outputs.push(drop_if_useless(temp, lambda: recorder.ticks > 0))
        outputs.enter_context(recorder)
        functions.append(Recording(recorder))
    if video is not None:
        functions.append(video)
    outputs.enter_context(filming(video, recorder))
    return functions

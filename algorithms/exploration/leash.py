"""Connected exploration's leash against walls (ours): the moves a robot may make on its
tether, and the walls its leash cannot know; the same in both worlds (a MuJoCo robot's
moves are its control ticks' ``(v, omega)``, a graph-world robot's its steps along its
edge).

The tether (:class:`~algorithms.exploration.tether.Tether`) knows ranges, not walls. A
robot keeps the moves it made since its parents were last all in radio reach (its
*trail*); when a wall comes between it and a parent (the parent is gone from its
ranging: on the MuJoCo robots as soon as the link fades, before it is cut) it drives
them backwards until the link is back, never back into a vertex
area it has given up (the trail is forgotten when it tells the stations it left one),
nor off a vertex centre it reached (forgotten there too). The way along its leg in which
the wall cut a link (+1 on, -1 back) is then closed to it for the rest of the leg, or
until it has a new parent: it stands there as if the leash had stopped it (so it calls a
relay, rule 6), and may still walk back along its leg unless a wall cut a link on the
way back too.
"""

from __future__ import annotations

from collections.abc import Mapping

from collections.abc import Callable, Sequence
from typing import Any

from algorithms.exploration.tether import Tether


class Leash:
    """One robot's leash on its body (module docstring)."""

    def __init__(self, tether: Tether) -> None:
        self.tether = tether
        self._trail: list = []  # its moves since its parents were all linked
        self._occluded: set[int] = set()  # the ways (+1 on, -1 back) a wall cut a link
        self._cut: set = set()  # the parents whose links a wall cut
        self._parents_then = tether.parents

    @staticmethod
    def _way(back: bool) -> int:
        return -1 if back else 1

    def cut_off(self, around: Mapping) -> bool:
        """Whether a parent is missing from its radio neighbours ``around``."""
        return not all(q in around for q in self.tether.parents)

    def check(self, move: Any, step: Sequence[float], around: Mapping, back: bool,
              no_backing: bool, reserve: bool = True) -> Sequence[float] | None:
        """The ``step`` (m, the robot's displacement) of ``move`` that the leash, or a wall
        met on this way, forbids, or None: the move may go, and joins the trail (``move``
        None: the robot stays). ``back``: it walks back along its leg (and, with
        ``reserve``, may use the tether's reserve); ``no_backing``: it stands on a vertex
        centre or makes a move that is never backed out of (an arrival, a U-turn): its
        trail is forgotten."""
        wanted = None
        if move is not None:
            if self._way(back) in self._occluded or not self.tether.may_step(
                    step, around, back=back and reserve):
                wanted = step
            else:
                self._trail.append(move)
        if no_backing:
            self._trail = []
        if self.tether.parents != self._parents_then:  # a new parent: try again
            self.new_leg()
        self._parents_then = self.tether.parents
        return wanted

    def cut_on_this_way(self, back: bool):
        """The parents a wall cut it from on the way it drives (empty if none)."""
        return self._cut if self._way(back) in self._occluded else ()

    def undo(self, around: Mapping, back: bool, reverse: Callable[[Any], Any],
             may: Callable[[Any], bool] = lambda move: True) -> Any:
        """A parent's link is gone: this way is closed, and the last move of its trail
        comes back reversed (``reverse(move)``), or None when nothing is left to undo or
        ``may(move)`` says the move may not be undone now (a body in its way: the move
        stays on the trail)."""
        self._occluded.add(self._way(back))
        self._cut |= {q for q in self.tether.parents if q not in around}
        if not self._trail or not may(self._trail[-1]):
            return None
        return reverse(self._trail.pop())

    def forget(self) -> None:
        """Forget its trail (it gave up a vertex area: it never backs into it)."""
        self._trail = []

    def new_leg(self) -> None:
        """A new leg, or a new parent: no walls known, nothing to undo."""
        self._occluded, self._trail, self._cut = set(), [], set()

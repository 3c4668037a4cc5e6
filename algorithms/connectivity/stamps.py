"""Ahmadi & Stone: distributed biconnectivity check with stamped messages.

Robots pass stamped messages ``(T, (S))`` (Definition 6): a robot that receives a
biconnectivity-type message not yet stamped by itself appends its id and broadcasts it
(Algorithm 1, :func:`stamp_relay`). So every simple path of the robot graph is walked by a
message, which is why the worst case is factorial (Ahmadi & Stone: "(n - 1)! messages in each
time period" per robot).

* CR-FILL fills CR_R, the robots connected to R: every id stamped on a received "CR"
  message.
* DCR-FILL (Algorithm 2, :func:`dcr_members`) fills DCR_R, the robots doubly connected to
  R: when R receives ``(S1, R, S2)`` with ``|S2| > 1``, the robots of S2 close a loop with R.
* The check (Algorithm 3, :class:`BiconnectivityCheck`) waits 3Nc, compares
  ``|DCR_R| = |CR_R|`` and exchanges DC-TRUE / DC-FALSE with the neighbours: by Theorem 1,
  R and one neighbour doubly connected to everyone make the graph biconnected. The
  initiator decides within 6Nc + 2c.

Time is counted in control ticks, c = 1 tick; N (Assumption 1) is the maximum team size.

Choices where the paper defers to (Ahmadi & Stone 2006a), which we do not have:

* When to originate CR messages: a robot originates ``("CR", (R.id))`` once per check, the
  first time it takes part (it starts the check, or hears any message of it). That is the
  least that makes CR_R complete: R only learns of robots whose own messages reach it.
* DCR-FILL is originated only by robots that run Algorithm 3 (the initiator, and its
  neighbours on CHECK-REQUEST), as Algorithm 2 line 1 says. A non-initiator that has
  already joined the CR-FILL does not restart it on CHECK-REQUEST ("unless they are already
  running it"); it still waits its own 3Nc, which gives the paper's 6Nc + 2c.
* CR_R and DCR_R start empty for a check; one :class:`BiconnectivityCheck` is one check
  (Algorithm 2's "reset on the first DCR message" is that). Run a new object per check.
* DC-TRUE / DC-FALSE heard before a robot's own wait is over are kept (a neighbour of the
  initiator hears the initiator's verdict right when it starts) and read when it evaluates.
* A robot that is doubly connected to everyone it knows but hears no verdict from a
  neighbour by 6Nc + 2c after it started decides false (it has no neighbour, so the team
  is not biconnected). The paper does not say.
* "Connected" needs the team size n (the roster): connected iff ``|CR_R| + 1 = n``. The
  check's answer, ``biconnected``, is Algorithm 3's result and connected: Algorithm 3 alone
  looks only at R's component. For n = 2 this says "not biconnected" (one path is not two
  internally disjoint ones, Definition 3), where networkx calls K2 biconnected.
"""

from __future__ import annotations

from collections.abc import Hashable, Iterable
from typing import NamedTuple

from algorithms.robot import Message

CR = "CR"
DCR = "DCR"
CHECK_REQUEST = "CHECK-REQUEST"
DC_TRUE = "DC-TRUE"
DC_FALSE = "DC-FALSE"


class Stamped(NamedTuple):
    """Definition 6: message ``(T, (S))``, type ``kind`` and stamps in stamping order."""

    kind: str
    stamps: tuple


class Control(NamedTuple):
    """An unstamped message of Algorithm 3: CHECK-REQUEST, DC-TRUE or DC-FALSE."""

    kind: str


def stamp_relay(stamps: tuple, robot_id: Hashable) -> tuple | None:
    """Algorithm 1 line 2: the stamps to broadcast, ``(S, R.id)``, or None if R.id is in S."""
    return None if robot_id in stamps else stamps + (robot_id,)


def dcr_members(stamps: tuple, robot_id: Hashable) -> tuple:
    """Algorithm 2 lines 6-8: split S into ``(S1, R.id, S2)``; S2 if ``size(S2) > 1``.

    Those robots lie on a loop through R, so they are doubly connected to R. A message
    that comes straight back (``size(S2) = 1``) or was never stamped by R gives nothing.
    """
    if robot_id not in stamps:
        return ()
    s2 = stamps[stamps.index(robot_id) + 1 :]
    return s2 if len(s2) > 1 else ()


class BiconnectivityCheck:
    """One robot's part in one biconnectivity check (Algorithms 1-3 of Ahmadi & Stone).

    Args:
        robot_id: this robot's unique id (Assumption 3).
        team_size: n, the number of robots in the team (for "connected").
        max_robots: N of Assumption 1 (default n); the wait is 3N ticks.
        initiator: this robot starts the check at its first tick.

    After the decision, :attr:`result` is Algorithm 3's return value and
    :attr:`decided_at` the tick; :attr:`connected` / :attr:`biconnected` the verdicts.
    """

    def __init__(
        self,
        robot_id: Hashable,
        team_size: int,
        *,
        max_robots: int | None = None,
        initiator: bool = False,
    ) -> None:
        self.robot_id = robot_id
        self.team_size = team_size
        self.max_robots = team_size if max_robots is None else max_robots
        if self.max_robots < team_size:
            raise ValueError(f"N = {self.max_robots} is below the team size {team_size}")
        self.initiator = initiator
        #: CR_R: robots connected to this robot
        self.cr: set[Hashable] = set()
        #: DCR_R: robots doubly connected to this robot
        self.dcr: set[Hashable] = set()
        #: tick at which this robot started Algorithm 3 (None: not running it)
        self.started_at: int | None = None
        #: Algorithm 3's answer (None: undecided)
        self.result: bool | None = None
        self.decided_at: int | None = None
        self._cr_filled = False
        self._doubly_connected_to_all: bool | None = None
        self._heard_true = False
        self._heard_false = False

    @property
    def wait(self) -> int:
        """3Nc in ticks: CR-FILL and DCR-FILL are complete by then (Algorithm 3 line 1)."""
        return 3 * self.max_robots

    @property
    def connected(self) -> bool | None:
        """True iff every robot of the team is in CR_R (known once decided)."""
        return None if self.result is None else len(self.cr) + 1 == self.team_size

    @property
    def biconnected(self) -> bool | None:
        """Algorithm 3's result for a connected team; False if the team is not connected."""
        return None if self.result is None else self.result and bool(self.connected)

    def tick(
        self, now: int, inbox: Iterable[Message], neighbors: Iterable[Hashable] = ()
    ) -> list[Message]:
        """Process this tick's messages and answer with the messages to broadcast."""
        out: list[Message] = []
        if self.initiator and self.started_at is None:
            self._start_check(now, out)
        for message in inbox:
            payload = message.payload
            if isinstance(payload, Stamped):
                self._on_stamped(payload, out)
            elif payload.kind == CHECK_REQUEST:
                self._start_check(now, out)
            elif payload.kind == DC_TRUE:
                self._heard_true = True
            elif payload.kind == DC_FALSE:
                self._heard_false = True
        if self.started_at is not None and self.result is None:
            self._algorithm3(now, out)
        return out

    def _cr_fill(self, out: list[Message]) -> None:
        """CR-FILL: originate this robot's CR message, once per check."""
        if not self._cr_filled:
            self._cr_filled = True
            out.append(Message(Stamped(CR, (self.robot_id,))))

    def _start_check(self, now: int, out: list[Message]) -> None:
        """Algorithm 3 line 1: run CR-FILL and DCR-FILL (Algorithm 2 line 1)."""
        if self.started_at is not None:
            return
        self.started_at = now
        self._cr_fill(out)
        out.append(Message(Stamped(DCR, (self.robot_id,))))  # DCR-FILL

    def _on_stamped(self, message: Stamped, out: list[Message]) -> None:
        """Fill CR_R (CR-FILL) or DCR_R (Algorithm 2 lines 6-8), then relay (Algorithm 1)."""
        self._cr_fill(out)
        if message.kind == CR:
            self.cr.update(message.stamps)
            self.cr.discard(self.robot_id)
        else:
            self.dcr.update(dcr_members(message.stamps, self.robot_id))
        relayed = stamp_relay(message.stamps, self.robot_id)
        if relayed is not None:
            out.append(Message(Stamped(message.kind, relayed)))

    def _algorithm3(self, now: int, out: list[Message]) -> None:
        """Algorithm 3 lines 2-11, once this robot's 3Nc wait is over."""
        assert self.started_at is not None
        if self._doubly_connected_to_all is None and now >= self.started_at + self.wait:
            if self.initiator:
                out.append(Message(Control(CHECK_REQUEST)))  # line 2
            self._doubly_connected_to_all = len(self.dcr) == len(self.cr)  # line 3
            out.append(Message(Control(DC_TRUE if self._doubly_connected_to_all else DC_FALSE)))
            if not self._doubly_connected_to_all:
                self._decide(False, now)  # line 7
                return
        if self._doubly_connected_to_all:
            if self._heard_false:
                self._decide(False, now)  # line 9
            elif self._heard_true:
                self._decide(True, now)  # lines 10-11
            elif now >= self.started_at + 2 * self.wait + 2:
                self._decide(False, now)  # no neighbour answered by 6Nc + 2c

    def _decide(self, result: bool, now: int) -> None:
        self.result = result
        self.decided_at = now

"""Static message-passing harness: run a connectivity method on a team to its decision.

Each tick every robot (in team order) reads its inbox, sees its neighbours and answers
with messages to send, which the radio delivers at the end of the tick; one tick is the
papers' c. The robots are :class:`~algorithms.connectivity.participant.Participant`
controllers in a :class:`~mjswarm.worlds.static.StaticWorld`, run by the one :class:`~mjswarm.worlds.loop.Loop`. The harness counts messages from the radio's counters and stops at the deciding robot's
decision: the initiator (``stamps``, Ahmadi & Stone Algorithm 3: tick 6N + 2 at the latest) or
the reference (``tables`` / ``tables-2``, Le et al. with the gathering of
:class:`algorithms.connectivity.TableCheck`: tick 2N - 1).

The stamps method floods every simple path, so its cost is factorial on dense graphs.
The harness stops any method once more than ``message_cap`` messages have been sent; the
result then has ``capped = True`` and unknown (None) verdicts, and ``messages`` /
``rounds`` say how far it got.
"""

from __future__ import annotations

from collections.abc import Callable, Hashable, Mapping
from dataclasses import asdict, dataclass

from algorithms.connectivity import BiconnectivityCheck, TableCheck
from algorithms.connectivity.participant import MessagePassing, Participant, Verdict
from mjswarm.experiments.connectivity.team import Team
from mjswarm.errors import MjswarmError
from mjswarm.worlds.loop import Loop, LoopFunctions
from mjswarm.worlds.static import StaticWorld
from mjswarm.core.radio import Radio

#: Method names: Ahmadi & Stone's stamps, Le et al.'s tables and its forward-two variant.
METHODS: tuple[str, ...] = ("stamps", "tables", "tables-2")
#: Default limit on messages (transmissions) before a run is stopped as capped.
DEFAULT_MESSAGE_CAP = 200_000


@dataclass(frozen=True)
class CheckResult:
    """Outcome of one check. Verdicts are None when unknown (capped run).

    ``articulation_points`` (sorted ids) is None for ``stamps``, which does not find them;
    for the tables methods it covers the reference's component. ``messages`` counts
    transmissions (a broadcast is one), ``deliveries`` the copies received; ``rounds`` is
    the tick of the decision (c = 1 tick).
    """

    method: str
    robots: int
    initiator: str
    connected: bool | None
    biconnected: bool | None
    articulation_points: list[str] | None
    messages: int
    max_messages_per_robot: int
    deliveries: int
    rounds: int
    capped: bool

    def to_dict(self) -> dict:
        return asdict(self)


class _Until(LoopFunctions):
    """Stops the harness when ``until(loop)`` holds after a tick, or once more than
    ``cap`` messages were sent (checked after each tick: a tick adds at most one round of
    every robot's messages)."""

    def __init__(self, until: Callable[[Loop], bool], cap: int | None) -> None:
        self.until, self.cap, self.capped = until, cap, False

    def should_stop(self, loop: Loop) -> bool:
        if self.cap is not None and loop.world.radio.total_sent > self.cap:
            self.capped = True
            return True
        return self.until(loop)


class _Decision:
    """Watches the robots' reports for ``decider``'s :class:`Verdict` (the harness's
    stopping rule)."""

    def __init__(self, decider: Hashable) -> None:
        self.decider, self.verdict = decider, None

    def __call__(self, loop: Loop) -> bool:
        for robot, event in loop.reports:
            if robot == self.decider and type(event) is Verdict:
                self.verdict = event
        return self.verdict is not None


def drive(
    radio: Radio,
    robots: Mapping[Hashable, MessagePassing],
    until: Callable[[Loop], bool],
    *,
    start: int = 0,
    max_ticks: int = 10_000,
    message_cap: int | None = None,
) -> tuple[int, bool]:
    """Run ticks ``start, start + 1, ...`` until ``until(loop)`` holds after a tick (it
    reads the loop's reports, such as a :class:`~algorithms.connectivity.participant.
    Verdict`).

    ``robots`` maps radio ids to message-passing minds (``tick(now, inbox, neighbors)``),
    each run as a :class:`~algorithms.connectivity.participant.Participant` by one
    :class:`~mjswarm.worlds.loop.Loop` in a :class:`~mjswarm.worlds.static.StaticWorld`. A tick's messages are
    delivered at its end (``radio.last_batch`` counts them). Returns ``(last tick,
    capped)``; capped means more than ``message_cap`` messages were sent (checked after
    each tick).
    """
    stop = _Until(until, message_cap)
    loop = Loop(StaticWorld(radio, start), {r: Participant(m) for r, m in robots.items()},
                [stop])
    loop.run(max_ticks=max_ticks)
    if not loop.stopped:
        raise RuntimeError(f"no decision within {max_ticks} ticks")
    return start + loop.ticks - 1, stop.capped


def _checkers(method: str, ids: tuple, leader, max_robots: int | None) -> dict:
    """Every robot's mind for ``method``: the stamps check of Ahmadi & Stone or the
    connectivity tables of Le et al. (forwarding two tables with ``tables-2``)."""
    n = len(ids)
    if method == "stamps":
        return {r: BiconnectivityCheck(r, n, max_robots=max_robots, initiator=r == leader)
                for r in ids}
    forwards = 2 if method == "tables-2" else None
    return {r: TableCheck(r, leader, n, max_robots=max_robots, max_forwards=forwards)
            for r in ids}


def run_check(
    team: Team,
    method: str,
    *,
    range_m: float | None = None,
    initiator: str | None = None,
    max_robots: int | None = None,
    drop_prob: float = 0.0,
    seed: int | None = 0,
    message_cap: int | None = DEFAULT_MESSAGE_CAP,
) -> CheckResult:
    """Run ``method`` on ``team`` and report verdicts and message counts.

    Args:
        team: positions (metres) and optional explicit edges / walls.
        method: one of :data:`METHODS`.
        range_m: radio range d_c in metres (required unless the team has explicit edges).
        initiator: the robot that starts the check (stamps) or is the reference (tables);
            default the team's first robot.
        max_robots: N of Ahmadi & Stone Assumption 1 (default n); sets the timing.
        drop_prob: probability that the radio loses a message (the papers assume none).
        seed: seeds the radio's losses.
        message_cap: stop once more messages than this were sent (None: no cap).
    """
    if method not in METHODS:
        raise MjswarmError(f"unknown method {method!r} (choose from {', '.join(METHODS)})")
    ids = team.ids
    n = len(ids)
    leader = ids[0] if initiator is None else initiator
    if leader not in team.positions:
        raise MjswarmError(f"initiator {leader!r} is not a robot of {team.source}")
    if max_robots is not None and max_robots < n:
        raise MjswarmError(f"N (max robots) = {max_robots} is below the team size {n}")
    if message_cap is not None and message_cap < 1:
        raise MjswarmError(f"message cap must be at least 1, got {message_cap}")
    radio = team.radio(range_m, drop_prob=drop_prob, rng=seed)
    nodes = _checkers(method, ids, leader, max_robots)
    decision = _Decision(leader)
    rounds, capped = drive(radio, nodes, decision, message_cap=message_cap)
    verdict = None if capped else decision.verdict
    points = None if verdict is None else verdict.articulation_points
    return CheckResult(
        method=method,
        robots=n,
        initiator=leader,
        connected=None if verdict is None else verdict.connected,
        biconnected=None if verdict is None else verdict.biconnected,
        articulation_points=None if points is None else list(points),
        messages=radio.total_sent,
        max_messages_per_robot=max(radio.sent.values()),
        deliveries=sum(radio.received.values()),
        rounds=rounds,
        capped=capped,
    )

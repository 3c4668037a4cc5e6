"""The embodied explorer's modes: every move of :data:`~algorithms.exploration.explorer.
TRANSITIONS` driven through the robot's own inputs (its navigator's events, the stations'
answers, its tether), and no move outside the table.

The navigator, the tether and the connected exploration are stand-ins the test steers;
the explorer, its speed rule, vertex entry's messages and the body watch are the real ones.
"""

from __future__ import annotations

import math
from types import SimpleNamespace

import pytest

from algorithms.collision import CollisionRule
from algorithms.exploration import explorer as explorer_module
from algorithms.exploration.base import DONE, IDLE, Decision
from algorithms.exploration.entry import (
    GIVE_UP_S,
    STATION,
    EntryBlocked,
    EntryBusy,
    EntryDenied,
    EntryGranted,
    EntryRequest,
    GiveUp,
    LeftVertex,
    TurnedBack,
    Withdraw,
)
from algorithms.exploration.explorer import CLEAR_BEHIND_M, NO_BACKING, U_TURNING, Explorer
from algorithms.exploration.modes import TERMINAL, TRANSITIONS, Mode
from algorithms.exploration.leash import Leash
from algorithms.navigation import NavEvent, NavigatorState
from algorithms.navigation.navigator import NavigatorEvent
from algorithms.robot import Message, Observation

DT_S = 0.02
ANGLE = 0.0


def beacon() -> SimpleNamespace:
    return SimpleNamespace(id="b0", data=None, frame=None)


class Nav:
    """A navigator the test steers: its state, flags and events are set by hand."""

    def __init__(self) -> None:
        self.state = NavigatorState.SCANNING
        self.events: list[NavigatorEvent] = []
        self.on_lane = self.in_corridor = self.room_to_turn = self.at_vertex_area = False
        self.odometry = SimpleNamespace(distance_m=0.0, theta=0.0)
        self.edge_angles, self.arrived_angle = [ANGLE, math.pi], None
        self.line_filter, self.beacon_frame, self.heading_variance = None, None, 0.0
        self.turns = 0
        self.cal = SimpleNamespace(body_radius_m=0.075)

    def update(self, percept) -> tuple[float, float]:
        return (0.1, 0.0) if self.state is not NavigatorState.AT_VERTEX else (0.0, 0.0)

    def depart(self, angle: float) -> None:
        self.state = NavigatorState.LEAVING

    def turn_back(self) -> None:
        self.turns += 1  # a U-turn: off its lane until it finds the opposite one
        self.state = NavigatorState.LEAVING
        self.on_lane = self.in_corridor = self.room_to_turn = False

    def lane_bearings(self, bearings):
        return bearings

    def carried(self, percept) -> None:
        pass

    def arrive(self) -> None:
        self.state, self.arrived_angle = NavigatorState.AT_VERTEX, math.pi
        self.on_lane = self.in_corridor = self.room_to_turn = False
        self.events.append(NavigatorEvent(NavEvent.ARRIVED))


class Mind:
    """A strategy that answers from a script."""

    replans, stored_angles = True, None

    def __init__(self, *decisions: Decision) -> None:
        self.decisions = list(decisions)
        self.blocked: list[float] = []

    def on_vertex(self, beacon, angles, arrived_by) -> Decision:
        return self.decisions.pop(0) if self.decisions else IDLE

    def block(self, angle: float) -> None:
        self.blocked.append(angle)

    def give_up(self, angle: float) -> None:
        self.blocked.append(angle)

    def map_edges(self):
        return []


class Tied:
    """A tether and its connected exploration, as far as the explorer asks them."""

    me, parents, relay_trips, consulted, stops_part_way, mode = 0, (), 0, True, False, "explore"
    calls_relay = False

    def __init__(self, mind: Mind) -> None:
        self.mind, self.children, self.sense, self.stall = mind, set(), 1, False

    def ask(self, *args, **kwargs):
        return []

    hear = after = ask

    def beat(self, *args):
        return Message("beat")

    def stalled(self, now) -> bool:
        return self.stall

    def may_step(self, *args, back=False) -> bool:
        return True

    def holds(self) -> bool:
        return bool(self.children)

    def direction(self, progress: float) -> int:
        return self.sense

    def arrive(self, *args) -> None:
        pass

    arrived_back = retire = arrive

    def on_vertex(self, beacon, angles, arrived_by) -> Decision:
        return self.mind.on_vertex(beacon, angles, arrived_by)


class Robot:
    """One explorer with its stand-ins, and what it did."""

    def __init__(self, *decisions: Decision, entry: bool = True, tied: bool = False) -> None:
        self.mind = Mind(*decisions)
        self.x = Explorer(self.mind, SimpleNamespace(body_radius_m=0.075), None, 0.1,
                          CollisionRule(0.1, 1e-6, dt=DT_S) if entry else None,
                          control_dt_s=DT_S)
        self.nav = self.x.nav
        if tied:
            self.tie = Tied(self.mind)
            self.x.tether = self.x.connected = self.tie
            self.x.leash, self.x.body_watch = Leash(self.tie), None
        self.t, self.sent = 0.0, []
        self.moves: list[tuple[Mode, Mode]] = []
        enter = self.x._enter

        def recorded(mode: Mode) -> None:
            self.moves.append((self.x.mode, mode))
            enter(mode)
        self.x._enter = recorded

    def step(self, *payloads, dt: float = DT_S, at=beacon) -> Mode:
        self.t += dt
        inbox = tuple(Message(p, None, STATION) for p in payloads)
        command = self.x.step(Observation(0, self.t, (math.nan,) * 3, (math.nan,) * 3,
                                          (0.0, 0.0), inbox=inbox, beacon=at() if at else None))
        self.sent = [m.payload for m in command.messages if m.to == STATION]
        return self.x.mode

    def arrive(self, at=beacon) -> Mode:
        self.nav.arrive()
        return self.step(at=at)

    def on_lane(self, corridor: bool = True, room: bool = False) -> None:
        self.nav.state = NavigatorState.ON_EDGE
        self.nav.on_lane, self.nav.in_corridor, self.nav.room_to_turn = True, corridor, room


@pytest.fixture(autouse=True)
def steered(monkeypatch):
    monkeypatch.setattr(explorer_module, "percept", lambda *args: None)
    monkeypatch.setattr(explorer_module, "Navigator", lambda *args: Nav())


def go(*more: Decision) -> tuple[Decision, ...]:
    return (Decision("go", ANGLE), *more)


def asking(*more: Decision, tied: bool = False) -> Robot:
    r = Robot(*go(*more), tied=tied)
    assert r.arrive() is Mode.ASKING and r.sent == [EntryRequest(ANGLE)]
    return r


def leaving(*more: Decision) -> Robot:
    r = asking(*more)
    assert r.step(EntryGranted(True, ANGLE)) is Mode.LEAVING
    r.on_lane(corridor=False)
    return r


def on_lane(*more: Decision, room: bool = False) -> Robot:
    r = leaving(*more)
    r.on_lane(room=room)
    assert r.step() is Mode.ON_LANE and r.sent == [LeftVertex()]
    return r


def turn_asked() -> Robot:
    r = on_lane()
    assert r.step(EntryBlocked(ANGLE)) is Mode.TURN_ASKED
    assert r.sent == [TurnedBack(from_lane=False)] and r.mind.blocked == [ANGLE]
    return r


def walking_back_untold() -> Robot:
    r = on_lane(room=True)
    assert r.step(EntryBlocked(ANGLE)) is Mode.WALKING_BACK_UNTOLD and r.nav.turns == 1
    return r


def walking_back() -> Robot:
    r = walking_back_untold()
    r.on_lane()
    assert r.step() is Mode.WALKING_BACK and r.sent == [TurnedBack(from_lane=True)]
    return r


def test_decisions_at_a_vertex():
    r = Robot(IDLE, DONE)
    assert r.arrive() is Mode.IDLE
    assert r.step(dt=1.0) is Mode.IDLE  # before idle_wait_s
    assert r.step(dt=1.5) is Mode.FINISHED and r.x.finished
    assert r.moves[:3] == [(Mode.SCANNING, Mode.DECIDING), (Mode.DECIDING, Mode.IDLE),
                           (Mode.IDLE, Mode.DECIDING)]
    cut = Robot(Decision("cut off"))
    assert cut.arrive() is Mode.FINISHED and cut.sent[0].reason.startswith("cut off")
    free = Robot(*go(), entry=False)  # without vertex entry it departs at once
    assert free.arrive() is Mode.ON_LANE and free.sent == []


def test_a_grant_sends_it_off_and_its_corridor_frees_the_vertex_it_left():
    r = on_lane(*go())
    assert (Mode.ASKING, Mode.LEAVING) in r.moves and (Mode.LEAVING, Mode.ON_LANE) in r.moves
    assert r.arrive() is Mode.ASKING  # the next decision: go again


def test_a_queue_is_given_up_and_the_busy_answer_replans():
    r = asking(IDLE)
    assert r.step(dt=GIVE_UP_S) is Mode.GIVING_UP and r.sent == [GiveUp()]
    assert r.step(EntryBusy(ANGLE)) is Mode.IDLE and r.mind.blocked == [ANGLE]
    late = asking()
    late.step(dt=GIVE_UP_S)
    assert late.step(EntryGranted(True, ANGLE)) is Mode.LEAVING  # the grant overtook it
    blocked = asking()
    blocked.step(dt=GIVE_UP_S)
    assert blocked.step(EntryBlocked(ANGLE)) is Mode.IDLE


def test_a_blocked_vertex_is_decided_anew_on_the_centre():
    r = asking(IDLE)
    assert r.step(EntryBlocked(ANGLE + 1.0)) is Mode.ASKING  # not its request's angle
    assert r.step(EntryBlocked(ANGLE)) is Mode.IDLE and r.mind.blocked == [ANGLE]


def test_a_robot_with_children_gives_a_clear_grant_back_and_asks_again():
    r = asking(tied=True)
    r.tie.children = {1}
    assert r.step(EntryGranted(True, ANGLE)) is Mode.WITHDRAWN and r.sent == [Withdraw()]
    r.tie.children = set()
    assert r.step() is Mode.ASKING and r.sent == [EntryRequest(ANGLE)]
    again = asking(IDLE, tied=True)
    again.tie.children = {1}
    again.step(EntryGranted(True, ANGLE))
    assert again.step(EntryBlocked(ANGLE)) is Mode.IDLE


def test_a_relay_mission_from_a_centre_withdraws_and_decides_anew():
    r = asking(IDLE, tied=True)
    r.tie.relay_trips = 1
    assert r.step() is Mode.IDLE and Withdraw() in r.sent
    assert (Mode.ASKING, Mode.DECIDING) in r.moves
    held = asking(IDLE, tied=True)
    held.tie.children = {1}
    held.step(EntryGranted(True, ANGLE))
    held.tie.relay_trips = 1
    assert held.step() is Mode.IDLE and (Mode.WITHDRAWN, Mode.DECIDING) in held.moves


def test_a_relay_held_on_a_centre_on_its_way_withdraws_and_relays_there():
    """On its way, a relay that waits on a vertex centre for the next vertex as long as
    rule 6 lets a held relay wait becomes a relay there: it withdraws its request and
    stands (its strategy is not asked)."""
    r = asking(IDLE, tied=True)
    assert r.step() is Mode.ASKING and Withdraw() not in r.sent
    r.tie.mode = "relay"
    assert r.step() is Mode.IDLE and Withdraw() in r.sent
    assert (Mode.ASKING, Mode.DECIDING) in r.moves


def test_a_robot_leaving_that_calls_a_relay_gives_the_vertex_up_once_clear_of_its_centre():
    """Its relay may need the centre it leaves: once it calls one (rule 6) and is
    CLEAR_BEHIND_M out, a leaving robot tells the stations it left, short of its corridor;
    nearer, or not calling, it keeps the vertex."""
    r = asking(tied=True)
    assert r.step(EntryGranted(True, ANGLE)) is Mode.LEAVING
    r.on_lane(corridor=False)
    r.nav.odometry.distance_m = CLEAR_BEHIND_M
    assert r.step() is Mode.LEAVING and LeftVertex() not in r.sent  # not calling
    r.tie.calls_relay = True
    r.nav.odometry.distance_m = CLEAR_BEHIND_M - 0.01
    assert r.step() is Mode.LEAVING and LeftVertex() not in r.sent  # too near
    r.nav.odometry.distance_m = CLEAR_BEHIND_M
    assert r.step() is Mode.ON_LANE and r.sent == [LeftVertex()]


def test_a_relay_on_its_lane_gives_the_vertex_it_left_up_once_clear_of_its_centre():
    """A relay (rule 6) standing on its lane CLEAR_BEHIND_M or more out of the vertex it
    left, short of its corridor, tells the stations it left: it stands out of that area,
    which others need; nearer, it keeps the vertex."""
    r = asking(tied=True)
    assert r.step(EntryGranted(True, ANGLE)) is Mode.LEAVING
    r.on_lane(corridor=False)
    r.tie.mode = "relay"
    r.nav.odometry.distance_m = CLEAR_BEHIND_M - 0.01
    assert r.step() is Mode.LEAVING and LeftVertex() not in r.sent
    r.nav.odometry.distance_m = CLEAR_BEHIND_M
    assert r.step() is Mode.ON_LANE and r.sent == [LeftVertex()]


def test_a_leaving_robot_never_backs_off_the_start_of_the_lane_it_found():
    """The leash's trail is forgotten where the navigator finds its lane: the leaving's
    sidestep is dead-reckoned and its turns in place are no moves of the trail, so a
    retrace past the lane's start drives straight back along the lane's line, off every
    strip."""
    r = asking(tied=True)
    assert r.step(EntryGranted(True, ANGLE)) is Mode.LEAVING
    for _ in range(3):
        r.step()
    assert len(r.x.leash._trail) == 4  # leaving (the grant's tick too): moves on the trail
    r.on_lane(corridor=False)
    r.step()
    assert r.x.leash._trail == [(0.1, 0.0)]  # only the move made on its lane
    r.step()
    assert len(r.x.leash._trail) == 2


def test_a_robot_whose_hidden_parent_leaves_it_no_move_to_undo_stands_pinned():
    """The leash's retrace with its trail spent and the parent still out of its ranging:
    the robot stands as one its leash stopped, and tells its connected exploration it can
    take no step at all (it neither retreats nor offers itself: rule 6)."""
    r = asking(tied=True)
    assert r.step(EntryGranted(True, ANGLE)) is Mode.LEAVING
    r.on_lane(corridor=False)
    calls = []
    r.tie.after = lambda *args, **kwargs: calls.append((args, kwargs)) or []
    r.tie.parents = (5,)  # a parent its ranging does not show
    r.x.leash.forget()
    command = r.x.step(Observation(0, r.t + DT_S, (math.nan,) * 3, (math.nan,) * 3,
                                   (0.0, 0.0), beacon=None))
    assert (command.v_m_s, command.omega_rad_s) == (0.0, 0.0)
    (args, kwargs), = calls
    assert args[1] is not None and args[2] is False and kwargs == {"pinned": True}


def test_a_robot_on_its_way_in_to_a_centre_never_backs_out_when_its_parent_fades():
    """On its lane a robot whose parent's link fades drives its last moves backwards; on
    its way in to a vertex centre (the arrival's dead-reckoned sidestep, seek and spoke,
    NO_BACKING) and in a U-turn it stands pinned instead: resumed after a retrace, the
    arrival would end off the centre, the U-turn off its lanes."""
    assert NavigatorState.ARRIVING in NO_BACKING and NavigatorState.ON_EDGE not in NO_BACKING

    def faded_after_three_ticks_in(state: NavigatorState, u_turn: bool = False):
        r = asking(tied=True)
        r.step(EntryGranted(True, ANGLE))
        r.on_lane(room=u_turn)
        assert r.step() is Mode.ON_LANE
        r.tie.parents, r.nav.state = (5,), state
        calls = []
        r.tie.after = lambda *args, **kwargs: calls.append(kwargs) or []
        linked = {5: SimpleNamespace(range_m=0.5, bearing_rad=math.pi)}
        r.tie.sense = -1 if u_turn else 1  # rule 6 sends it back: with room, a U-turn
        for detections in (linked, linked, linked, {}):
            r.t += DT_S
            command = r.x.step(Observation(0, r.t, (math.nan,) * 3, (math.nan,) * 3,
                                           (0.0, 0.0), detections=detections, beacon=None))
        assert r.x.mode is (U_TURNING if u_turn else Mode.ON_LANE)
        return command, calls[-1]

    command, kwargs = faded_after_three_ticks_in(NavigatorState.ON_EDGE)
    assert command.v_m_s < 0.0 and kwargs == {}  # it backs its last move out
    command, kwargs = faded_after_three_ticks_in(NavigatorState.ARRIVING)
    assert (command.v_m_s, command.omega_rad_s) == (0.0, 0.0) and kwargs == {"pinned": True}
    # nor in a U-turn on its lane (also dead-reckoned: backed out part-way and resumed,
    # ``tri:2x3``'s 4 robots at 2 m, seed 2, lost one 25 cm off its lanes)
    command, kwargs = faded_after_three_ticks_in(NavigatorState.ON_EDGE, u_turn=True)
    assert (command.v_m_s, command.omega_rad_s) == (0.0, 0.0) and kwargs == {"pinned": True}


def test_a_robot_that_can_go_neither_on_nor_back_says_so_once():
    """Asking to turn back into the area it is leaving (rule 6 sends it back, no room to
    turn), a robot whose way on a wall closed tells the stations once: in a swap its own
    vertex went to another robot, and it would wait for an answer that never comes."""
    r = asking(tied=True)
    assert r.step(EntryGranted(True, ANGLE)) is Mode.LEAVING
    r.on_lane(corridor=False)
    r.nav.state = NavigatorState.LEAVING
    r.tie.sense = -1
    assert r.step() is Mode.TURN_ASKED_LEAVING and r.sent == [TurnedBack(from_lane=False)]
    r.tie.parents = (5,)  # its parent's link fades
    r.x.leash.forget()  # no move left to undo: its way on is closed
    linked = {5: SimpleNamespace(range_m=0.5, bearing_rad=math.pi)}
    said = []
    for detections in ({}, {}, linked, linked):
        r.t += DT_S
        command = r.x.step(Observation(0, r.t, (math.nan,) * 3, (math.nan,) * 3, (0.0, 0.0),
                                       detections=detections, beacon=None))
        said += [m.payload for m in command.messages if m.to == STATION]
        assert r.x.mode is Mode.TURN_ASKED_LEAVING
    assert said == [TurnedBack(from_lane=False, way_on_closed=True)]
    assert r.step(EntryGranted(True)) is Mode.WALKING_BACK and r.nav.turns == 1


def test_walking_back_from_the_area_it_leaves():
    r = leaving()
    assert r.step(EntryBlocked(ANGLE)) is Mode.TURN_ASKED_LEAVING
    r.on_lane()  # reaches its corridor before the answer
    assert r.step() is Mode.TURN_ASKED and r.sent == [LeftVertex()]
    granted = leaving()
    granted.step(EntryBlocked(ANGLE))
    assert granted.step(EntryGranted(True)) is Mode.WALKING_BACK and granted.nav.turns == 1


def test_walking_back_from_its_lane():
    r = turn_asked()
    assert r.step(EntryGranted(True)) is Mode.WALKING_BACK
    assert r.arrive() is Mode.IDLE and (Mode.WALKING_BACK, Mode.DECIDING) in r.moves
    swap = turn_asked()  # the vertex behind went to another robot: it goes on
    assert swap.arrive() is Mode.IDLE and (Mode.TURN_ASKED, Mode.DECIDING) in swap.moves
    turned = turn_asked()
    turned.nav.room_to_turn = True  # room before the answer: a U-turn
    assert turned.step(EntryBlocked(ANGLE)) is Mode.WALKING_BACK_UNTOLD
    assert turned.step(EntryGranted(True)) is Mode.WALKING_BACK and turned.sent == []
    told = walking_back()
    assert told.arrive() is Mode.IDLE


def test_rule_six_walks_back_without_vertex_entry():
    r = Robot(*go(), entry=False, tied=True)
    assert r.arrive() is Mode.ON_LANE
    r.on_lane()
    r.tie.sense = -1
    assert r.step() is Mode.WALKING_BACK and r.nav.turns == 1
    r.tie.sense = 1
    assert r.arrive() is Mode.IDLE


def test_it_stops_for_good_from_any_mode_and_ignores_the_stations_then():
    reach = {Mode.SCANNING: Robot, Mode.IDLE: lambda: Robot(IDLE), Mode.ASKING: asking,
             Mode.LEAVING: leaving, Mode.ON_LANE: on_lane, Mode.TURN_ASKED: turn_asked,
             Mode.WALKING_BACK_UNTOLD: walking_back_untold, Mode.WALKING_BACK: walking_back}
    for mode, make in reach.items():
        r = make()
        if mode is Mode.IDLE:
            r.arrive()
        assert r.x.mode is mode
        assert r.step(EntryDenied("broken frame")) is Mode.HALTED and r.x.halted
        assert r.step(EntryGranted(True, ANGLE)) is Mode.HALTED and r.sent == []
    lost = on_lane()
    lost.nav.events.append(NavigatorEvent(NavEvent.LOST, "no lane"))
    assert lost.step() is Mode.HALTED and lost.x.halted == "lost: no lane"
    blind = Robot(*go())
    assert blind.arrive(at=None) is Mode.HALTED  # no beacon where it arrived
    assert (Mode.DECIDING, Mode.HALTED) in blind.moves
    behind = walking_back()  # the vertex it walks back to closed too
    assert behind.step(EntryBlocked(None)) is Mode.HALTED


def test_the_stall_verdict_ends_any_mode():
    for make in (lambda: asking(tied=True), lambda: Robot(*go(), entry=False, tied=True)):
        r = make()
        if r.x.mode is Mode.SCANNING:
            r.arrive()
        r.tie.stall = True
        assert r.step() is Mode.INFEASIBLE and r.x.infeasible
        assert r.step() is Mode.INFEASIBLE


def test_moves_outside_the_table_are_refused():
    r = Robot()
    with pytest.raises(RuntimeError, match="cannot go from scanning to walking back"):
        r.x._enter(Mode.WALKING_BACK)
    r.x.mode = Mode.HALTED
    with pytest.raises(RuntimeError):
        r.x._enter(Mode.INFEASIBLE)  # nothing leaves a terminal mode


def test_every_move_of_the_table_is_driven():
    """Run every scenario above and collect the moves they make: each of the table's."""
    driven = set()
    tests = [test_decisions_at_a_vertex,
             test_a_grant_sends_it_off_and_its_corridor_frees_the_vertex_it_left,
             test_a_queue_is_given_up_and_the_busy_answer_replans,
             test_a_blocked_vertex_is_decided_anew_on_the_centre,
             test_a_robot_with_children_gives_a_clear_grant_back_and_asks_again,
             test_a_relay_mission_from_a_centre_withdraws_and_decides_anew,
             test_walking_back_from_the_area_it_leaves, test_walking_back_from_its_lane,
             test_rule_six_walks_back_without_vertex_entry]
    made = []
    original = Robot.__init__

    def tracking(self, *args, **kwargs):
        original(self, *args, **kwargs)
        made.append(self)
    Robot.__init__ = tracking
    try:
        for test in tests:
            test()
    finally:
        Robot.__init__ = original
    for r in made:
        driven |= set(r.moves)
    table = {(a, b) for a, targets in TRANSITIONS.items() for b in targets}
    assert table - driven == set()
    assert driven - table - {(a, b) for a, b in driven if b in TERMINAL} == set()

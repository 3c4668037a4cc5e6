"""The navigator's states: every move of :data:`~algorithms.navigation.navigator.
NAVIGATOR_TRANSITIONS` driven by what ends its motions (a seek that finds its line or
fails, a scan, the lane's end, the corridor wall seen and gone, a pass's follow) and by
its commands (``depart``, ``turn_back``, ``pass_body``), and no move outside the table.
The MuJoCo runs of ``tests/test_navigation.py`` and ``tests/test_passing.py`` drive the
same moves with real sensors."""

from __future__ import annotations

import math
from types import SimpleNamespace

import pytest

from algorithms.navigation import NavEvent, NavigatorState
from algorithms.navigation.motions import SeekLine
from algorithms.navigation.navigator import NAVIGATOR_TRANSITIONS, Corridor, Leg, Navigator
from algorithms.navigation.percept import percept
from mjswarm.core.simulation import Simulation
from mjswarm.core.world import Pose2D, world_spec
from mjswarm.worlds.navigation import calibration, conventions

S = NavigatorState
FOUND, FAILED = SimpleNamespace(failed=False), SimpleNamespace(failed=True)


@pytest.fixture(scope="module")
def body():
    geometry = Simulation(world_spec([Pose2D(0.0, 0.0)])).geometry
    return calibration(geometry), conventions(geometry)


class Driven:
    """A navigator whose moves are recorded."""

    def __init__(self, body) -> None:
        self.nav = Navigator(*body, 0.0, 0.1)
        self.moves: list[tuple[S, S]] = []
        enter = self.nav._enter

        def recorded(state: S) -> None:
            self.moves.append((self.nav.state, state))
            enter(state)
        self.nav._enter = recorded

    def at_vertex(self) -> Navigator:
        nav = self.nav
        nav.begin_at_vertex()
        nav._scanned(SimpleNamespace(full_turn=None, start=0.0, swept=2 * math.pi,
                                     mids=[0.0, math.pi]))
        assert nav.state is S.AT_VERTEX and nav.edge_angles == [0.0, math.pi]
        return nav

    def on_lane(self) -> Navigator:
        nav = self.at_vertex()
        nav.depart(0.0)
        nav._found_lane(FOUND)
        assert nav.state is S.ON_EDGE and nav.corridor is Corridor.BEFORE_WALL
        return nav

    def in_corridor(self) -> Navigator:
        nav = self.on_lane()
        wall = nav.conv.wall_distance_m
        for _ in range(3):
            nav._watch_wall(wall)
            nav.odometry.distance_m += nav.conv.min_wall_run_m
        assert nav.corridor is Corridor.BESIDE_WALL and nav.in_corridor
        return nav

    def vertex_ahead(self) -> Navigator:
        nav = self.in_corridor()
        for _ in range(10):
            nav._watch_wall(math.nan)
        assert nav.vertex_detected and nav.at_vertex_area
        return nav

    def arriving(self) -> Navigator:
        nav = self.vertex_ahead()
        nav._lane_ended(nav._lane)
        assert nav.state is S.ARRIVING
        return nav

    def passing(self) -> Navigator:
        nav = self.in_corridor()
        nav.pass_body(0.05)
        assert nav.state is S.STEPPING_ACROSS and not nav.on_lane and nav.in_corridor
        nav._found_opposite(FOUND)
        assert nav.state is S.PASSING
        return nav


def scenarios(body) -> list[Driven]:
    """Drive each move once; return the navigators (their recorded moves)."""
    made = []

    def drive() -> Driven:
        made.append(Driven(body))
        return made[-1]

    nav = drive().arriving()
    nav._start_scan()  # on the centre: the arrival's scan
    assert nav.state is S.SCANNING
    assert drive().arriving().turn_back() is None  # back to the lane's end, a U-turn
    assert made[-1].nav.state is S.LEAVING and made[-1].nav.leg is Leg.BACK
    nav = drive().arriving()
    nav._found_spoke(FAILED)
    assert nav.state is S.LOST
    nav = drive().at_vertex()
    nav.depart(0.0)
    nav.turn_back()  # still on the centre it left: a scan there
    assert nav.state is S.SCANNING and nav.leg is Leg.BACK
    nav = drive().at_vertex()
    nav.depart(0.0)
    nav.odometry.x += nav.conv.strip_width_m  # out of the centre, short of its corridor:
    nav.turn_back()  # by odometry to the spoke it left by
    assert nav.state is S.ARRIVING
    nav = drive().at_vertex()
    nav.depart(0.0)
    nav._found_lane(FAILED)
    assert nav.state is S.LOST
    nav = drive().on_lane()
    nav.turn_back()
    assert nav.state is S.ARRIVING
    nav = drive().in_corridor()
    nav.odometry.distance_m += 0.1
    assert nav.room_to_turn
    nav.turn_back()  # a U-turn onto the opposite lane
    assert nav.state is S.LEAVING
    nav = drive().on_lane()
    nav._lane_ended(nav._lane)  # no wall seen: not its lane
    assert nav.state is S.LOST and "before any corridor wall" in nav.events[-1].reason
    nav = drive().passing()
    nav._passed(SimpleNamespace(reached=True, heading=0.0))
    assert nav.state is S.STEPPING_ACROSS
    nav._rejoined(FOUND)
    assert nav.state is S.ON_EDGE
    nav = drive().passing()
    nav._passed(SimpleNamespace(reached=True, heading=0.0))
    nav._rejoined(FAILED)
    assert nav.state is S.LOST
    nav = drive().in_corridor()
    nav.pass_body(0.05)
    nav._found_opposite(FAILED)
    assert nav.state is S.LOST
    nav = drive().passing()
    nav._passed(SimpleNamespace(reached=False, heading=0.0))  # the lane ended beside it
    assert nav.state is S.LOST
    nav = drive().passing()
    for _ in range(10):
        nav._watch_wall(math.nan)  # the corridor ends during the pass
    nav._lane_ended(nav._lane)
    assert nav.state is S.ARRIVING
    return made


def test_every_move_of_the_table_is_driven(body):
    driven = set().union(*(set(d.moves) for d in scenarios(body)))
    table = {(a, b) for a, targets in NAVIGATOR_TRANSITIONS.items() for b in targets}
    assert table - driven == set()
    assert driven - table == set()


def test_moves_outside_the_table_are_refused(body):
    nav = Navigator(*body, 0.0, 0.1)
    with pytest.raises(RuntimeError, match="needs the robot on an edge"):
        nav.turn_back()
    with pytest.raises(RuntimeError, match="cannot go from at_vertex to passing"):
        nav._enter(S.PASSING)
    nav.begin_at_vertex()
    nav._scanned(SimpleNamespace(full_turn=None, start=0.0, swept=2 * math.pi, mids=[0.0]))
    nav.depart(0.0)
    nav._found_lane(FAILED)
    with pytest.raises(RuntimeError, match="cannot go from lost to scanning"):
        nav.begin_at_vertex()


def test_a_strip_ends_only_ahead_of_where_the_centre_last_saw_it():
    """:class:`~algorithms.navigation.motions.CentreEnd`: the centre off the strip for
    ``END_CONFIRM_TICKS`` past where it was last on is the strip's end; off behind that
    point (the robot driven backwards off the strip's start) is none, until the robot
    has come forward past it."""
    from algorithms.navigation.motions import END_CONFIRM_TICKS, CentreEnd

    end = CentreEnd()
    end.update(True, 1.000)
    assert all(end.update(False, 1.000 - 0.002 * k) is None for k in range(1, 10))
    assert end.update(False, 1.001) is None  # forward again: the count starts
    found = [end.update(False, 1.001 + 0.002 * k) for k in range(1, END_CONFIRM_TICKS)]
    assert found[-1] is not None and 1.000 < found[-1] < 1.002


def test_a_lane_backed_off_its_start_by_the_leash_has_not_ended(body):
    """hex:3x3, 6 robots at 3 m, connected, 0.1 m/s: R3 finds its lane at 270.00 s, a
    wall cuts its parent's link two ticks later, and the leash's retrace drives it 7 mm
    back (its navigator counting the ticks: :meth:`Navigator.carried`), its centre
    sensor off the lane's start. Standing there for a new parent, its navigator keeps
    the lane (a lane that ends with no corridor wall seen is not its lane: it would stop
    for good), and once it drives on it follows the lane from its start."""
    nav = Navigator(*body, 0.0, 0.1)
    cal, dt = nav.cal, 0.02
    wheels = [0.0, 0.0]

    def tick(centre: bool, v: float | None = None, carried: bool = False):
        """One control tick: the readings in, the wheels turned by the navigator's
        command, or by ``v`` (m/s, straight; ``carried``: the leash drives it)."""
        reading = [cal.line_floor_m] * 3
        reading[1] -= 0.002 * centre  # a strip under the centre sensor
        seen = percept(reading, (math.nan,) * 3, tuple(wheels), nav.line_filter)
        if carried:
            nav.carried(seen)
            command = (v, 0.0)
        else:
            command = nav.update(seen)
        speed, omega = command if v is None else (v, 0.0)
        for side, sign in ((0, -1.0), (1, 1.0)):
            wheels[side] += (speed + sign * omega * cal.track_m / 2.0) / cal.wheel_radius_m * dt
        return command

    for _ in range(20):  # on a centre: the line filter learns the floor
        tick(False, 0.0)
    nav.begin_at_vertex()
    nav._scanned(SimpleNamespace(full_turn=None, start=0.0, swept=2 * math.pi,
                                 mids=[0.0, math.pi]))
    nav.depart(0.0)
    for _ in range(2000):  # the sidestep, then the seek finds the lane
        if nav.state is S.ON_EDGE:
            break
        tick(isinstance(nav._plan[0][0], SeekLine))
    assert nav.state is S.ON_EDGE
    for _ in range(2):
        tick(True)
    for k in range(6):  # the retrace: back off the lane's start
        tick(k < 2, -0.1, carried=True)
    for _ in range(50):  # it stands, the leash closed ahead of it
        assert tick(False, 0.0)[0] > 0.0
    assert nav.state is S.ON_EDGE and nav.events[-1].kind is not NavEvent.LOST
    for _ in range(20):  # on again, to the lane's start
        if nav.odometry.distance_m >= nav._lane._end._last_on_m:
            break
        tick(False)
    for _ in range(10):
        tick(True)
    assert nav.state is S.ON_EDGE and nav.corridor is Corridor.BEFORE_WALL


def test_a_robot_too_near_the_vertex_behind_for_a_u_turn_goes_back_along_the_spoke(body):
    """In its corridor but without :attr:`~Navigator.room_to_turn`, a U-turn would end
    with its line sensors short of where the opposite lane starts: it goes back by
    odometry to the outer end of the spoke it left by and follows that spoke in."""
    nav = Driven(body).in_corridor()
    assert nav.in_corridor and not nav.room_to_turn
    nav.turn_back()
    assert nav.state is S.ARRIVING and nav.leg is Leg.BACK
    seek = [m for m, _ in nav._plan if isinstance(m, SeekLine)]
    assert len(seek) == 1 and math.isclose(seek[0].heading, math.pi)

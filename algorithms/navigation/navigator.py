"""A robot's way around a line-marked arena, from its own sensors only (Nagavarapu et al., Sec. 5).

The arena conventions (the marks a robot is built to read, not the graph): every edge has
two lane strips ``lane_offset_m`` either side of its centre line, and a robot drives on
the one to its left; walls line each edge, so the left IR sensor sees a wall on an edge
and none at a vertex ("the proximity sensor detects a vertex by detecting the absence of
an obstacle", Sec. 5); at each vertex a short centre-line *spoke* per incident edge runs
from ``spoke_inner_radius_m`` to ``spoke_radius_m``.

Behaviours, chained as plans of :mod:`~algorithms.navigation.motions`:

* **on an edge**: follow the lane; once the left wall has been seen for
  ``min_wall_run_m`` and then lost, the vertex is detected; the lane then ends;
* **arriving**: shift right by ``lane_offset_m`` onto the centre line (turn 60 degrees,
  drive, turn back), find and follow the incoming spoke to its inner end, drive
  ``line_ahead_m + spoke_inner_radius_m`` to stand on the vertex centre. The approach
  runs at most at ``APPROACH_SPEED_M_S`` whatever the cruising speed, and once aligned
  with the spoke the robot holds its direction and watches only the centre sensor
  (:class:`~.motions.FollowSpoke`), so a neighbouring spoke's inner end, within a side
  sensor's reach when edges are 45-90 degrees apart, cannot carry it away;
* **discovering edges**: rotate once in place (:class:`~.motions.Scan`); every spoke
  crossed gives an incidence angle, measured with encoder odometry. The spoke the robot
  came by lies opposite the lane's direction (measured on the lane, in the odometry
  frame): it is reported at exactly that angle, and its crossing tells how far the robot
  stands off-centre across it (:func:`off_centre_correction`). Scans turn
  counter-clockwise and clockwise in turn: each calibrates the odometry's track, but a
  residual scale error would add up over a long run's scans if they all turned one way
  (a lone robot's heading, without re-anchoring, over the 260 legs of ``lattice:10x10``
  at 0.2 m/s);
* **re-anchoring** (:meth:`Navigator.reanchor`): at a vertex whose beacon already stores
  angles, the caller rotates the robot's frame onto them (:func:`frame_offset`); once the
  robot has found slip (its odometry's distance scale), only part of the way, by the
  weights of the two frames' variances (:func:`fuse_frames`, frame
  fusion);
* **passing** (:meth:`Navigator.pass_body`, ours): round a body that stands on
  its lane, on the opposite lane: step square across to it, follow that lane
  until it is four body radii past where the body's front was, watching the corridor
  wall on its right (the right IR sees it there as the left IR does from its own lane),
  then sidestep back and follow its own lane on. If that wall ends during the pass (the
  body stands near the corridor's end), it stays on the opposite lane and arrives from
  it (the centre line is then to its left);
* **leaving**: sidestep from the vertex centre to the left of the chosen spoke by
  ``lane_offset_m`` and find the lane ahead. (Not along the spoke first: two robots
  leaving the two ends of one edge at once would then face each other on its centre line,
  where the collision rule stops both, Nagavarapu et al. eq. (27) with ``beta = 0``.)

Choices: the approach and departure shifts are open-loop odometry manoeuvres at 60
degrees; the vertex-centre estimate has the accuracy of line following plus a 8 cm
odometry drive (about a millimetre along the spoke, a few across it, which the incoming
spoke's crossing corrects), which keeps scan angles within about a degree.
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Sequence
from dataclasses import dataclass
from enum import Enum

from algorithms.navigation.motions import (
    Drive,
    FollowLine,
    FollowLineAlong,
    FollowSpoke,
    Scan,
    SeekLine,
    Turn,
    wrap,
)
from algorithms.navigation.odometry import Odometry, RobotCalibration
from algorithms.navigation.percept import LineFilter, Percept, WallWatch

SHIFT_ANGLE = math.radians(60.0)
#: Room (m) beyond touching that a pass leaves between the robot and the body it passed
#: when it steps onto the centre line, its lane having ended early (``_lane_ended``).
PASS_MARGIN_M = 0.02
#: The least angle (rad) between two edges of a vertex the arena marks allow.
MIN_EDGE_GAP = math.radians(45.0)
#: Top speed (m/s) of the approach to a vertex centre (finding and following the spoke,
#: the last drive): the spoke's end, which places the robot on the centre, is then seen
#: within a millimetre of travel per control tick whatever the cruising speed (at 0.2 m/s
#: and 50 Hz a tick is 4 mm, and scan angles err by up to 4 degrees).
APPROACH_SPEED_M_S = 0.05


@dataclass(frozen=True)
class ArenaConventions:
    """The arena marks a robot is built to read (metres, radians); see module docstring."""

    lane_offset_m: float
    spoke_inner_radius_m: float
    spoke_radius_m: float
    wall_distance_m: float  # left IR reading of the corridor wall from the lane
    strip_width_m: float  # width of every floor strip, lanes and spokes
    lane_start_m: float  # the least distance along its edge from a vertex centre of a lane
    wall_tolerance_m: float = 0.012
    min_wall_run_m: float = 0.05
    max_seek_m: float = 0.40


class NavEvent(Enum):
    """What a navigator reports to its robot's other parts (``Navigator.events``)."""

    LEFT_VERTEX = "left the vertex"
    VERTEX_DETECTED = "vertex detected"  # the left wall ended
    ARRIVED = "arrived"  # on a vertex centre with its edges measured (also after a launch)
    LOST = "lost"  # lost its line: needs help (the paper's robots were placed back by hand)
    PASSED = "passed a body"  # off the opposite lane after :meth:`Navigator.pass_body`


@dataclass(frozen=True)
class NavigatorEvent:
    """One navigator event; ``reason`` says why for LOST."""

    kind: NavEvent
    reason: str = ""

    def __str__(self) -> str:
        return f"{self.kind.value}: {self.reason}" if self.reason else self.kind.value


class NavigatorState(Enum):
    """What a navigator's body is doing; :data:`NAVIGATOR_TRANSITIONS` lists every move."""

    SCANNING = "scanning"
    AT_VERTEX = "at_vertex"  # edges known, waiting for depart()
    LEAVING = "leaving"
    ON_EDGE = "on_edge"
    ARRIVING = "arriving"
    STEPPING_ACROSS = "stepping_across"  # passing a body: square across between the lanes
    PASSING = "passing"  # round a body on its lane, on the opposite lane
    LOST = "lost"  # lost its line: needs help (the paper's robots were placed back by hand)


#: Every move of a navigator's state, with what makes it.
NAVIGATOR_TRANSITIONS: dict[NavigatorState, dict[NavigatorState, str]] = {
    NavigatorState.AT_VERTEX: {
        NavigatorState.SCANNING: "begin_at_vertex() (a launch)",
        NavigatorState.LEAVING: "depart()"},
    NavigatorState.SCANNING: {NavigatorState.AT_VERTEX: "the turn is complete"},
    NavigatorState.LEAVING: {
        NavigatorState.ON_EDGE: "a sensor finds its own lane",
        NavigatorState.ARRIVING: "turn_back() short of its corridor",
        NavigatorState.SCANNING: "turn_back() still on the centre it left",
        NavigatorState.LOST: "no lane strip ahead"},
    NavigatorState.ON_EDGE: {
        NavigatorState.ARRIVING: "the lane ends after its wall; turn_back() short of "
                                 "its corridor",
        NavigatorState.LEAVING: "turn_back() in its corridor: a U-turn",
        NavigatorState.STEPPING_ACROSS: "pass_body()",
        NavigatorState.LOST: "the lane ends with the wall beside it, or before any wall"},
    NavigatorState.ARRIVING: {
        NavigatorState.SCANNING: "on the vertex centre",
        NavigatorState.LEAVING: "turn_back(): back to where its lane ended, a U-turn",
        NavigatorState.LOST: "no spoke at the vertex"},
    NavigatorState.STEPPING_ACROSS: {
        NavigatorState.PASSING: "on the opposite lane",
        NavigatorState.ON_EDGE: "back on its own lane, past the body",
        NavigatorState.LOST: "no opposite lane, or its own lane not found again"},
    NavigatorState.PASSING: {
        NavigatorState.STEPPING_ACROSS: "a body diameter past the body",
        NavigatorState.ARRIVING: "the corridor ended during the pass",
        NavigatorState.LOST: "the opposite lane ended beside the body"},
    NavigatorState.LOST: {},
}


#: The states in which a robot follows one of its edge's lanes (or steps between them).
ON_A_LANE = frozenset({NavigatorState.ON_EDGE, NavigatorState.STEPPING_ACROSS,
                       NavigatorState.PASSING})


class Corridor(Enum):
    """How far along its corridor a robot on a lane is (vertex detection by its IR)."""

    BEFORE_WALL = "before its wall"
    BESIDE_WALL = "beside its wall"  # seen for ``min_wall_run_m``: in its corridor
    VERTEX_AHEAD = "vertex ahead"  # the wall, once seen, ended


class Leg(Enum):
    """Which way a robot travels its edge: out to the vertex ahead, or back to the one
    it left (:meth:`Navigator.turn_back`)."""

    OUT = "out"
    BACK = "back"


class Navigator:
    """One robot's navigation state machine.

    Args:
        calibration: the robot's own body constants.
        conventions: the arena marks it reads.
        heading: the robot's initial heading in its reference frame (rad), e.g. from a
            compass at the root; all incidence angles are reported in this frame.
        speed_m_s: cruising speed.
        turn_rate_rad_s: in-place turn and scan rate.
    """

    def __init__(self, calibration: RobotCalibration, conventions: ArenaConventions,
                 heading: float, speed_m_s: float,
                 turn_rate_rad_s: float = 1.0) -> None:
        self.cal, self.conv = calibration, conventions
        self.odometry = Odometry(calibration, theta=heading)
        #: its line detection (:func:`~.percept.percept` reads through it)
        self.line_filter = LineFilter(calibration.line_floor_m)
        #: its vertex detection: the left IR's wall, debounced
        self.wall_watch = WallWatch(conventions.wall_distance_m, conventions.wall_tolerance_m)
        self.speed = speed_m_s
        self._approach_speed = min(speed_m_s, APPROACH_SPEED_M_S)
        self.turn_rate = turn_rate_rad_s
        #: what its body is doing (:data:`NAVIGATOR_TRANSITIONS`)
        self.state = NavigatorState.AT_VERTEX
        self.edge_angles: list[float] = []
        self.arrived_angle: float | None = None
        self.events: list[NavigatorEvent] = []
        self._plan: deque = deque()
        self._incoming: float | None = None
        self._scans = 0
        self._tracks: list[float] = []  # effective track estimates, one per scan (m)
        #: the heading's variance (rad^2) at the odometry's ``wheel_sq`` of
        #: ``_var_wheel_sq`` (:attr:`heading_variance`); 0 at the start (robots start
        #: aligned with the common frame)
        self._var_rad2 = 0.0
        self._var_wheel_sq = 0.0
        self._fused_scan = -1  # the scan whose angles it fused last
        #: after :meth:`reanchor` fused frames: the beacon's frame ``(offset, variance)``
        #: updated by this visit, for the caller to write back; else None
        self.beacon_frame: tuple[float, float] | None = None
        self._lane: FollowLine | None = None
        self._left: tuple[float, float, float] | None = None  # centre x, y and angle it left by
        #: x, y and heading (odometry) where its lane ended
        self._lane_end: tuple[float, float, float] | None = None
        self.leg = Leg.OUT
        self._wall_run_start: float | None = None
        self.corridor = Corridor.BEFORE_WALL
        self._wall_first_m: float | None = None  # odometry distance where its wall began
        #: which side of its lane the edge's centre line lies: -1 right (its own lane),
        #: +1 left (the opposite lane, passing a body)
        self._centre_side = -1

    def _enter(self, state: NavigatorState) -> None:
        """Move to ``state``: only along :data:`NAVIGATOR_TRANSITIONS`."""
        if state not in NAVIGATOR_TRANSITIONS[self.state]:
            raise RuntimeError(f"a navigator cannot go from {self.state.value} to "
                               f"{state.value}")
        self.state = state

    @property
    def vertex_detected(self) -> bool:
        """Whether its corridor wall, once seen, has ended: the vertex is ahead."""
        return self.corridor is Corridor.VERTEX_AHEAD

    # ---------------------------------------------------------------- control
    def begin_at_vertex(self) -> None:
        """Start on a vertex centre (the root): discover its edges."""
        self._start_scan()

    def depart(self, angle: float) -> None:
        """Leave the vertex along the spoke at incidence ``angle`` (rad, own frame)."""
        if self.state is not NavigatorState.AT_VERTEX:
            raise RuntimeError(f"depart() needs the robot at a vertex, it is {self.state.value}")
        self._plan = deque([
            *self._shift(angle, +1),
            (SeekLine(angle, self.speed, self.conv.max_seek_m, self._own_lane(angle)),
             self._found_lane),
        ])
        self._left = (self.odometry.x, self.odometry.y, angle)
        self._enter(NavigatorState.LEAVING)
        self.events.append(NavigatorEvent(NavEvent.LEFT_VERTEX))

    def turn_back(self) -> None:
        """Head back to the vertex it left, from anywhere on its edge.

        With :attr:`room_to_turn` in its corridor: a U-turn onto the opposite lane (face
        back, sidestep two lane offsets to the left, find the lane), then on as along any
        edge: the vertex is where the new left wall ends (however little of it it saw:
        after a U-turn at the far end of a short edge a few centimetres may be left; where
        its lane ends, if it saw none), and the arrival is by the edge it left along.
        Arriving at the vertex ahead (its lane ended): back by odometry to where the lane
        ended, then the same U-turn. Short of that room (leaving, on the lane before its
        wall, or in its corridor too near the vertex behind): by odometry to the point of
        the spoke it left by from which, facing the centre, its line sensor lies a strip's
        width in from the spoke's inner end, then in along the spoke to the centre and a
        scan, as on any arrival, by the edge it left along. (A U-turn there would end with
        its line sensors short of where the opposite lane starts, and its seek find a
        neighbouring edge's lane or nothing: on ``hex:2x2``, 4 robots at 1.5 m,
        connected, 0.15 m/s, seed 2, a robot turning 0.31 m along its edge would end 0.20
        m from the centre, its sensors short of the lane's start at 0.16 m, and be lost.
        Nor by the spoke's outer end: there its body reaches within 0.12 m of a robot
        waiting where the opposite lane's wall ends, 0.26 m from the centre, and each
        stops for the other for good: on ``lattice:3x3``, 3 robots at 1.2 m, connected,
        0.1 m/s, seed 1.) Still on the centre it left (leaving, its axle within half a
        strip's width of where it stood: it has only turned): a scan there, as on any
        arrival, by the edge it left along. (Out to the spoke point and in again would take
        it towards whatever held it on its way out: on ``tree1``, 5 robots at 2 m,
        connected, 0.1 m/s, seed 1, a relay that never left its centre drove 9 cm out
        towards the robot it served, on the lane it had wanted, and stood there for good.)
        All ours (Nagavarapu et al.'s robots never turned back)."""
        if self.state not in (NavigatorState.LEAVING, NavigatorState.ON_EDGE,
                              NavigatorState.ARRIVING):
            raise RuntimeError(f"turn_back() needs the robot on an edge, it is {self.state.value}")
        x, y, angle = self._left
        self._incoming, self.leg = angle, Leg.BACK
        odo = self.odometry
        if (self.state is NavigatorState.LEAVING
                and math.hypot(odo.x - x, odo.y - y) <= self.conv.strip_width_m / 2.0):
            self._start_scan()
            return
        if self.room_to_turn or self.state is NavigatorState.ARRIVING:
            plan = []
            if self.state is NavigatorState.ARRIVING:
                ex, ey, heading = self._lane_end
                toward = math.atan2(ey - odo.y, ex - odo.x)
                plan = [(Turn(toward, self.turn_rate), None),
                        (Drive(math.hypot(ex - odo.x, ey - odo.y), toward,
                               self._approach_speed), None)]
            else:
                heading = self._lane.direction(odo.theta)
            back = wrap(heading + math.pi)
            self._plan = deque([
                *plan,
                (Turn(back, self.turn_rate), None),
                *self._shift(back, +1, 2.0 * self.conv.lane_offset_m),
                (SeekLine(back, self.speed, self.conv.max_seek_m), self._found_lane),
            ])
            self._enter(NavigatorState.LEAVING)
            return
        # to the spoke it left by, its line sensor a strip's width in from the inner
        # end, then in along it as on any arrival
        out = self.conv.spoke_inner_radius_m + self.conv.strip_width_m + self.cal.line_ahead_m
        px, py = x + out * math.cos(angle), y + out * math.sin(angle)
        toward, inward = math.atan2(py - odo.y, px - odo.x), wrap(angle + math.pi)
        self._plan = deque([
            (Turn(toward, self.turn_rate), None),
            (Drive(math.hypot(px - odo.x, py - odo.y), toward, self._approach_speed), None),
            (Turn(inward, self.turn_rate), None),
            (SeekLine(inward, self._approach_speed, self.conv.max_seek_m), self._found_spoke),
            (FollowSpoke(self._approach_speed), self._spoke_ended),
        ])
        self._enter(NavigatorState.ARRIVING)

    def pass_body(self, ahead_m: float) -> None:
        """Pass a body standing ``ahead_m`` (m, the front IR's reading from its rim) ahead
        on its lane, on the opposite lane (module docstring). Its centre then ends
        ``ahead_m + 4 body_radius_m`` along the lane from where it starts: the body's
        centre is ``ahead_m + 2 r`` ahead, and it steps back once a body diameter beyond
        it. The steps across are square to the lane (:meth:`_sidestep`), so it passes a
        round body of its own kind with ``2 lane_offset_m - 2 r`` to spare (3 cm for the
        Spark V on 9 cm lane offsets). The caller makes sure the opposite lane carries
        nobody meanwhile."""
        if self.state is not NavigatorState.ON_EDGE or self.cal.body_radius_m is None:
            raise RuntimeError("pass_body() needs the robot on its lane and its radius")
        odo = self.odometry
        heading = self._lane.direction(odo.theta)
        follow = FollowLineAlong(FollowLine(self.speed), heading, (odo.x, odo.y),
                                 ahead_m + 4.0 * self.cal.body_radius_m)
        self._plan = deque([
            *self._sidestep(heading, -1),
            (SeekLine(heading, self.speed, self.conv.max_seek_m), self._found_opposite),
            (follow, self._passed),
        ])
        self._enter(NavigatorState.STEPPING_ACROSS)

    def _sidestep(self, heading: float, side: int) -> list:
        """Cross to the other lane of its edge, to the left (side=+1) or right (-1) of
        ``heading``, square to it: a turn in place, two lane offsets straight across, a
        turn back. Unlike :meth:`_shift`'s diagonal it gains no ground along the lane, so
        a round body however near ahead keeps its distance."""
        return self._shift(heading, side, 2.0 * self.conv.lane_offset_m, math.pi / 2.0)

    def update(self, percept: Percept) -> tuple[float, float]:
        """Advance one control tick; return the ``(v, omega)`` command (m/s, rad/s)."""
        self.odometry.update(percept.encoders)
        if self.state is NavigatorState.ON_EDGE:
            self._watch_wall(percept.ir[0])
        elif self.state is NavigatorState.PASSING:
            self._watch_wall(percept.ir[2])  # the corridor's other wall, seen from its lane
        while self._plan:
            motion, on_done = self._plan[0]
            command = motion.step(self.odometry, percept)
            if command is not None:
                return command
            self._plan.popleft()
            if on_done is not None:
                on_done(motion)
        return 0.0, 0.0

    def carried(self, percept: Percept) -> None:
        """One control tick in which its robot drives the body itself (the leash's
        retrace: its last moves backwards, :class:`~algorithms.exploration.leash.Leash`):
        its odometry counts the wheels' turns, and its plan waits. The motion under way
        then resumes from where the body is, by odometry; a lane or spoke backed off its
        strip's start has not ended (:class:`~.motions.CentreEnd`)."""
        self.odometry.update(percept.encoders)

    @property
    def heading_variance(self) -> float:
        """Its own estimate of its heading's variance (rad^2) against the common frame:
        what it had at its last fusion (or 0 at the start) plus what slip added since
        (:meth:`~.odometry.Odometry.heading_variance_since`; 0 without slip found)."""
        return self._var_rad2 + self.odometry.heading_variance_since(self._var_wheel_sq)

    @property
    def fuses_frames(self) -> bool:
        """Whether it fuses frames at a revisit (:meth:`reanchor`): once its odometry has
        found slip (a distance scale other than 1). Noise-free and line-noise runs never
        find any and re-anchor fully."""
        return self.odometry.slip_sigma > 0.0

    def reanchor(self, stored: Sequence[float],
                 beacon_frame: tuple[float, float] | None = None) -> float:
        """Re-anchor the heading frame to a beacon's stored incidence angles (rad).

        Rotates the odometry heading, the edge angles just measured and the arrival angle
        by :func:`frame_offset` of the measured angles against ``stored``; returns that
        rotation (rad). With ``beacon_frame`` (the beacon's ``(offset, variance)``: how
        far its stored angles are believed to lie from the common frame, rad and rad^2)
        and :attr:`fuses_frames`, by :func:`fuse_frames`' share of it instead: its
        :attr:`heading_variance` shrinks accordingly, and :attr:`beacon_frame` is what the
        caller writes back into the beacon. A robot fuses once per scan: a second call at
        the same vertex (after idling, a queue given up) measured nothing new and turns
        it by nothing."""
        self.beacon_frame = None
        delta_rad = frame_offset(self.edge_angles, stored)
        if beacon_frame is not None and self.fuses_frames:
            if self._fused_scan == self._scans:
                return 0.0
            self._fused_scan = self._scans
            delta_rad, var, offset, beacon_var = fuse_frames(
                delta_rad, self.heading_variance, *beacon_frame)
            self._var_rad2, self._var_wheel_sq = var, self.odometry.wheel_sq
            self.beacon_frame = (offset, beacon_var)
        self.odometry.correct_heading(delta_rad)
        self.edge_angles = sorted((a + delta_rad) % (2.0 * math.pi) for a in self.edge_angles)
        if self.arrived_angle is not None:
            self.arrived_angle = (self.arrived_angle + delta_rad) % (2.0 * math.pi)
        return delta_rad

    @property
    def in_corridor(self) -> bool:
        """On an edge's lane (or passing on the opposite one) and has seen its corridor
        wall (``min_wall_run_m`` of it)."""
        return self.state in ON_A_LANE and self.corridor is not Corridor.BEFORE_WALL

    @property
    def room_to_turn(self) -> bool:
        """Far enough into its corridor for a U-turn (:meth:`turn_back`) to keep clear of
        the vertex area behind: the U-turn's sidestep carries it
        ``2 lane_offset_m / tan(60 deg)`` back, and it is at least ``min_wall_run_m`` more
        past where its wall began (a vertex area ends where its walls begin)."""
        if not (self.on_lane and self.in_corridor):
            return False
        back_m = 2.0 * self.conv.lane_offset_m / math.tan(SHIFT_ANGLE)
        return self.odometry.distance_m - self._wall_first_m >= back_m + self.conv.min_wall_run_m

    @property
    def on_lane(self) -> bool:
        """Following an edge's lane (not yet arriving at the vertex at its end)."""
        return self.state is NavigatorState.ON_EDGE

    def lane_bearings(self, bearings: dict[int, float]) -> dict[int, float]:
        """Bearings (rad, from the robot's nose, as its bearing sensor reports them) turned
        into its lane's frame: ``beta + theta - lane direction``, the lane's direction
        estimated in the odometry frame from the ticks aligned with it so far
        (:meth:`~.motions.FollowLine.direction`, all of the lane). The speed rule's
        ``beta = 0`` is "ahead on the same lane" (Nagavarapu et al. eq. (27)); a line follower's
        nose swings a few degrees about its lane (more when its line filter lags),
        and a robot standing on the centre of the vertex beyond the next one, 5-13 degrees
        off the lane within the sensor's metre, came within the rule's 2.6 degree cone of
        the nose (``arena2``, 4 robots, 0.2 m/s, 0.5 mm line noise, kinematic: the robot
        stopped for it, and it waited for the vertex the stopped robot held). The robot's own
        turning also leaves the rate (eq. (17)): the rate is that of the bearing seen along
        the lane. Off a lane: unchanged."""
        if self.state is not NavigatorState.ON_EDGE or self._lane is None:
            return bearings
        theta = self.odometry.theta
        swing = wrap(theta - self._lane.direction(theta, last=None))
        return {p: beta + swing for p, beta in bearings.items()}

    def _own_lane(self, angle: float):
        """Leaving along ``angle``: whether the strips the line sensors see now include
        the lane sought (the left lane of that edge) rather than a lane of a neighbouring
        edge of this vertex (ours). Lanes start where they no longer cross their
        neighbours' (:func:`mjswarm.arena.geometry.lane_setback`), at 27 cm for edges 45
        degrees apart, where the right lane of the edge 45 degrees to the left comes
        within 2.5 cm of the lane sought: a robot set off 2.4 degrees off its edge found
        that lane's corner with its left sensor first and followed it (``wheel:4@8``, 1
        robot, 0.1 m/s, line noise 0.5 mm, kinematic, seed 0: lost). A sensor's strip counts as the lane sought when that lane's line is the nearest
        of the vertex's lane lines (both lanes of every edge measured here, on the
        robot's side of the centre; positions by odometry from the centre it left). A
        sensor on the lane sought lies within half a strip (15 mm) of its line, and the
        nearest other lane line is about 4 cm away where that lane starts (edges 45 or 60
        degrees apart; 7 cm at 90, and farther beyond the start), so the check errs only
        when the robot's estimate of where the sensor is errs by 5-20 mm across the lane
        (5 mm for a sensor on the strip's edge nearest the other line). The spokes of the
        vertex's edges (centre-line strips from ``spoke_inner_radius_m`` to
        ``spoke_radius_m``) are among the other lines, as segments: where edges meet at 45
        degrees the right sensor ends the sidestep about 5 mm beside the outer end of the
        spoke 45 degrees to the left, and with odometry a few millimetres and a degree off
        it saw that spoke, 9 cm short of where the lane sought starts, and followed it off
        the vertex (``wheel:4@8``, 4 robots, 0.1 m/s, every noise with slip 0.05,
        kinematic, seed 1: lost). So the lane sought counts only from a strip's width short
        of ``lane_start_m`` along its edge (no lane starts nearer), where a sensor on it is
        at least 10 cm from any spoke. None without the sensor spacing."""
        spacing = self.cal.line_spacing_m
        others = [a for a in self.edge_angles if abs(wrap(a - angle)) > MIN_EDGE_GAP / 2.0]
        if spacing is None or not others:
            return None
        cx, cy = self.odometry.x, self.odometry.y
        offset, ahead = self.conv.lane_offset_m, self.cal.line_ahead_m
        inner, outer = self.conv.spoke_inner_radius_m, self.conv.spoke_radius_m
        sought_from = self.conv.lane_start_m - self.conv.strip_width_m
        lanes = [(angle, offset)] + [(a, side * offset) for a in others for side in (1, -1)]
        spokes = [(math.cos(a), math.sin(a)) for a in self.edge_angles]

        def nearest_lane(x: float, y: float) -> int:
            """The index in ``lanes`` of the line nearest ``(x, y)`` (m, odometry frame);
            -1 when a spoke is nearer than every lane (or no lane lies ahead)."""
            best, which = math.inf, -1
            for k, (a, lateral) in enumerate(lanes):
                c, s = math.cos(a), math.sin(a)
                along = (x - cx) * c + (y - cy) * s
                if along <= (sought_from if k == 0 else 0.0):
                    continue
                d = abs(-(x - cx) * s + (y - cy) * c - lateral)
                if d < best:
                    best, which = d, k
            for c, s in spokes:
                along = min(max((x - cx) * c + (y - cy) * s, inner), outer)
                if math.hypot(x - cx - along * c, y - cy - along * s) < best:
                    return -1
            return which

        def ours(odo: Odometry, line: tuple[bool, bool, bool]) -> bool:
            c, s = math.cos(odo.theta), math.sin(odo.theta)
            return any(on and nearest_lane(odo.x + ahead * c - side * s,
                                           odo.y + ahead * s + side * c) == 0
                       for on, side in zip(line, (spacing, 0.0, -spacing)))
        return ours

    @property
    def at_vertex_area(self) -> bool:
        """About to enter a vertex area: on the lane with the vertex detected (the left
        wall has ended), or already arriving."""
        return ((self.state in ON_A_LANE and self.vertex_detected)
                or self.state is NavigatorState.ARRIVING)

    # ---------------------------------------------------------------- plans
    def _shift(self, heading: float, side: int, distance_m: float | None = None,
               angle: float = SHIFT_ANGLE) -> list:
        """Sidestep ``distance_m`` (default ``lane_offset_m``) to the left (side=+1) or
        right (-1) of ``heading``, driving at ``angle`` (rad) to it."""
        diagonal = heading + side * angle
        across = self.conv.lane_offset_m if distance_m is None else distance_m
        return [
            (Turn(diagonal, self.turn_rate), None),
            (Drive(across / math.sin(angle), diagonal, self.speed), None),
            (Turn(heading, self.turn_rate), None),
        ]

    def _found_lane(self, seek: SeekLine) -> None:
        if seek.failed:
            self._lose("no lane strip ahead after leaving the vertex")
            return
        self._enter(NavigatorState.ON_EDGE)
        self.corridor = Corridor.BEFORE_WALL
        self._wall_run_start = None
        self._wall_first_m = None
        self._lane = FollowLine(self.speed)
        self._plan = deque([(self._lane, self._lane_ended)])

    def _found_opposite(self, seek: SeekLine) -> None:
        if seek.failed:
            self._lose("no opposite lane beside the body it passes")
            return
        self._enter(NavigatorState.PASSING)
        self._wall_run_start = None

    def _passed(self, follow: FollowLineAlong) -> None:
        """Past the body: back onto its own lane, or (the corridor ended meanwhile) on
        along the opposite lane to its end and the arrival from there."""
        if follow.reached and not self.vertex_detected:
            self._enter(NavigatorState.STEPPING_ACROSS)
            self._plan = deque([
                *self._sidestep(follow.heading, +1),
                (SeekLine(follow.heading, self.speed, self.conv.max_seek_m), self._rejoined),
            ])
            return
        if not self.vertex_detected:
            self._lose("the opposite lane ended beside the body it passed")
            return
        self._lane, self._centre_side = follow.line, +1
        self.events.append(NavigatorEvent(NavEvent.PASSED))
        if follow.reached:  # on to the opposite lane's end
            self._plan = deque([(follow.line, self._lane_ended)])
        else:  # the lane ended before it was clear of the body: on, then square across
            short_m = 2.0 * self.cal.body_radius_m - self._square_clearance_m
            self._lane_ended(follow.line, follow.remaining_m(self.odometry) - short_m)

    @property
    def _square_clearance_m(self) -> float:
        """How far past a passed body's centre (m, along the lane) the robot's centre must
        be to step square from the opposite lane onto the centre line, ``lane_offset_m``
        beside the body on its lane, and stay ``PASS_MARGIN_M`` clear of touching it:
        ``sqrt((2 r + margin)^2 - offset^2)``, 0.144 m for the Spark V (a diameter and the
        margin straight along would be 0.17 m). The 2.6 cm matter: the station closes a
        vertex for a body within ``VERTEX_CLEAR_RADIUS_M`` (0.255 m) of its centre, and a
        body just beyond it leaves a robot stepping across at 0.17 m past it with its centre
        sensor beyond the incoming spoke's inner end; its seek finds the spoke on the far
        side of the centre and it stands 15 cm off the vertex (``arena2``, 4 robots, seed
        0, ``robot:1@25.6``: the second robot would stop, the map be lost)."""
        reach_m = 2.0 * self.cal.body_radius_m + PASS_MARGIN_M
        return math.sqrt(reach_m**2 - self.conv.lane_offset_m**2)

    def _rejoined(self, seek: SeekLine) -> None:
        if seek.failed:
            self._lose("its lane not found after passing a body")
            return
        self._enter(NavigatorState.ON_EDGE)
        self._wall_run_start = None
        self._lane = FollowLine(self.speed)
        self._plan = deque([(self._lane, self._lane_ended)])
        self.events.append(NavigatorEvent(NavEvent.PASSED))

    def _watch_wall(self, ir_m: float) -> None:
        """Vertex detection: the left wall (``ir_m``: the left IR's reading; the right
        one's while passing on the opposite lane), once seen on this edge, disappears.

        A wall is an IR reading within ``wall_tolerance_m`` of ``wall_distance_m``, the
        distance from the lane to the corridor wall: a robot passing on the left is seen
        at other, changing distances and is not taken for a wall (NaN never matches). It
        is gone once :class:`~.percept.WallWatch` has missed it for several readings in a
        row under IR noise (one noisy reading is no vertex)."""
        travelled = self.odometry.distance_m
        if self.wall_watch(ir_m):
            if self._wall_run_start is None:
                self._wall_run_start = travelled
            if self._wall_first_m is None:
                self._wall_first_m = travelled
            # a robot that turned back may have little wall left beside it (a U-turn at
            # the far end of a short edge): any of it will do
            run = 0.0 if self.leg is Leg.BACK else self.conv.min_wall_run_m
            if (travelled - self._wall_run_start >= run
                    and self.corridor is Corridor.BEFORE_WALL):
                self.corridor = Corridor.BESIDE_WALL
        else:
            self._wall_run_start = None
            if self.corridor is Corridor.BESIDE_WALL:
                self.corridor = Corridor.VERTEX_AHEAD
                self.events.append(NavigatorEvent(NavEvent.VERTEX_DETECTED))

    def _lane_ended(self, lane: FollowLine, clear_m: float = 0.0) -> None:
        """The lane ended: arrive (module docstring). ``clear_m`` > 0 (m): it passed a
        body on the opposite lane, and the lane ended before it was clear of the body
        (:attr:`_square_clearance_m`); it drives that far on first, and steps onto the
        centre line square to the lane, since the diagonal shift's turn toward the body's
        side would touch it (``arena2`` with 4 robots, seed 0, ``robot:1@91``: 23 contact
        events before)."""
        if not self.vertex_detected and self.leg is Leg.OUT:
            self._lose("lane ended with the wall still beside the robot"
                       if self.corridor is Corridor.BESIDE_WALL
                       else "lane ended before any corridor wall was seen (not its lane?)")
            return
        self._enter(NavigatorState.ARRIVING)
        heading = lane.direction(self.odometry.theta, last=None)
        self._lane_end = (self.odometry.x, self.odometry.y, heading)
        # the lane's direction in the odometry frame, carried to the scan: the incoming
        # spoke lies opposite it (a better reference than the angle measured at the last
        # vertex, which carries that scan's error)
        self._incoming = (heading + math.pi) % (2.0 * math.pi)
        side, self._centre_side = self._centre_side, -1
        onto_centre = self._shift(heading, side) if clear_m <= 0.0 else [
            (Drive(clear_m, heading, self._approach_speed), None),
            *self._shift(heading, side, angle=math.pi / 2.0)]
        self._plan = deque([
            *onto_centre,
            (SeekLine(heading, self._approach_speed, self.conv.max_seek_m), self._found_spoke),
            (FollowSpoke(self._approach_speed), self._spoke_ended),
        ])

    def _found_spoke(self, seek: SeekLine) -> None:
        if seek.failed:
            self._lose("no spoke found at the vertex")

    def _spoke_ended(self, spoke: FollowSpoke) -> None:
        """The sensor passed the spoke's inner end: the centre is ``line_ahead +
        spoke_inner_radius`` beyond where the axle was then."""
        heading = spoke.direction(self.odometry.theta)
        beyond = self.odometry.distance_m - spoke.ended_at_m
        centre = self.cal.line_ahead_m + self.conv.spoke_inner_radius_m - beyond
        self._plan.append((Drive(centre, heading, self._approach_speed),
                           lambda _: self._start_scan()))

    def _start_scan(self) -> None:
        self._enter(NavigatorState.SCANNING)
        self._scans += 1
        direction = 1 if self._scans % 2 else -1  # alternate: see the module docstring
        width = self._spoke_width
        self._plan = deque([(Scan(self.turn_rate, direction, width / 2.0, width),
                             self._scanned)])

    @property
    def _spoke_width(self) -> float:
        """The angle (rad) a ``strip_width_m`` spoke spans at the line sensor's
        ``line_ahead_m`` around the axle: 35 degrees for the 30 mm strips at 50 mm. Runs
        of the scan's centre sensor narrower than half of it are no spoke (a noisy
        flicker is a tick's 1.2 degrees); runs much wider hold several
        (:func:`~.motions.spokes_in_run`)."""
        return 2.0 * math.asin(self.conv.strip_width_m / 2.0 / self.cal.line_ahead_m)

    def _scanned(self, scan: Scan) -> None:
        """Calibrate, then turn the scan's crossings into incidence angles."""
        used = self.odometry.track_m
        if scan.full_turn is not None:
            # odometry over-reads rotation by full_turn / 2 pi: the effective track is
            # that much wider; average over all scans so one noisy turn counts little
            self._tracks.append(used * scan.full_turn / (2.0 * math.pi))
            self.odometry.calibrate(sum(self._tracks) / len(self._tracks), len(self._tracks),
                                    exact_crossings=self.line_filter.window == 1)
        scale = used / self.odometry.track_m  # true rotation per odometry rotation
        self.odometry.theta = scan.start + scan.swept * scale
        angles = sorted((scan.start + m * scale) % (2.0 * math.pi) for m in scan.mids)
        self.edge_angles = angles
        self.arrived_angle = None
        if self._incoming is not None and angles:
            self.arrived_angle = self._incoming
            self.edge_angles = off_centre_correction(
                angles, self.arrived_angle, self.cal.line_ahead_m)
        self._enter(NavigatorState.AT_VERTEX)
        self.leg = Leg.OUT
        self.events.append(NavigatorEvent(NavEvent.ARRIVED))

    def _lose(self, why: str) -> None:
        self._enter(NavigatorState.LOST)
        self._plan.clear()
        self.events.append(NavigatorEvent(NavEvent.LOST, why))


#: The variance (rad^2) of one vertex's frame as a scan measures it, without slip: each
#: spoke's angle errs by about 0.9 degrees (the scan's sampling and standing off-centre;
#: measured on the noise grid, ``python -m mjswarm.experiments.stress --noise``). A new beacon's frame holds its dropper's heading variance plus
#: this; a revisit's :func:`frame_offset` errs by about as much.
SCAN_FRAME_VAR = math.radians(0.9) ** 2


def fuse_frames(delta_rad: float, robot_var: float, beacon_offset: float,
                beacon_var: float) -> tuple[float, float, float, float]:
    """A scalar Kalman update of a robot's heading and a beacon's frame on a revisit
    (ours: frame fusion): ``(correction, robot variance after,
    beacon offset after, beacon variance after)``, rad and rad^2.

    ``delta_rad`` is :func:`frame_offset` of the robot's measured angles onto the beacon's
    stored ones: the beacon frame's error minus the robot's, plus a scan's error
    (``SCAN_FRAME_VAR``). The beacon believes its frame lies ``beacon_offset`` off the
    common frame, with variance ``beacon_var``; the robot believes its own heading
    unbiased, with variance ``robot_var``. The innovation ``y = delta - beacon_offset``
    has variance ``S = robot_var + beacon_var + SCAN_FRAME_VAR``:

    * the robot turns by ``k y``, ``k = robot_var / S``: fully onto the beacon's frame
      when its own heading is much less sure (plain re-anchoring, ``k = 1``), hardly at
      all when the beacon's is (a robot fresh from the root meeting a deep vertex);
    * the beacon's offset moves by ``(beacon_var / S) y`` towards the robot's frame, and
      its variance shrinks alike. Its stored angles never move (they name its edges in
      every robot's incidence matrix, matched within ``ANGLE_TOLERANCE``); the offset is
      what a later visitor subtracts.

    The two errors are taken as independent (no cross-covariance is kept): a robot back at
    a vertex whose frame it took before shares part of its error with it, and the update
    then trusts the pair a little too much (over the noise grid's slip runs, ``python -m
    mjswarm.experiments.stress --noise``, the robots' squared
    errors average 1.3 times their variance, the beacons' 1.0 times)."""
    s = robot_var + beacon_var + SCAN_FRAME_VAR
    y = delta_rad - beacon_offset
    k, kb = robot_var / s, beacon_var / s
    return k * y, robot_var * (1.0 - k), beacon_offset + kb * y, beacon_var * (1.0 - kb)


def frame_offset(measured: Sequence[float], stored: Sequence[float]) -> float:
    """The rotation (rad, in (-pi, pi]) that best carries ``measured`` angles onto
    ``stored`` ones: the circular mean of ``stored_k - m_k``, ``m_k`` the measured angle
    nearest to ``stored_k``. Edges at a vertex are at least 45 degrees apart and a
    robot's heading error stays far below half that, so nearest is the same edge. Every
    edge counts, not only the one the robot came by: each stored and measured angle errs
    by up to a degree or so (the scan's sampling and standing off-centre), and the mean
    over d edges errs about sqrt(d) times less.
    """
    diffs = [wrap(s - min(measured, key=lambda m: abs(wrap(m - s)))) for s in stored]
    return math.atan2(sum(map(math.sin, diffs)), sum(map(math.cos, diffs)))


def off_centre_correction(angles: list[float], incoming: float, radius: float) -> list[float]:
    """Spoke directions corrected for the robot scanning off the vertex centre.

    The centre line sensor sweeps a circle of ``radius`` around the axle. With the axle
    at offset ``p`` from the vertex centre, it crosses the spoke of direction ``alpha``
    at the heading ``phi`` where ``cross(p + radius u(phi), u(alpha)) = 0``, i.e.
    ``radius sin(alpha - phi) = -cross(p, u(alpha))``. The incoming spoke's direction is
    known (the robot came along it), so its crossing gives the offset across it,
    ``p = -radius sin(phi_in - alpha_in) n_in`` (``n_in`` its left normal; the offset
    along it is taken as zero: the approach stops there to a few millimetres). Every
    other spoke is then solved by fixed-point iteration. The incoming spoke is reported
    at exactly ``incoming``. Angles in radians, [0, 2 pi).
    """
    phi_in = min(angles, key=lambda a: abs(wrap(a - incoming)))
    s = -radius * math.sin(phi_in - incoming)
    px, py = -s * math.sin(incoming), s * math.cos(incoming)
    corrected = []
    for phi in angles:
        if phi == phi_in:
            corrected.append(incoming % (2.0 * math.pi))
            continue
        alpha = phi
        for _ in range(4):
            across = px * math.sin(alpha) - py * math.cos(alpha)  # cross(p, u(alpha))
            alpha = phi - math.asin(max(-1.0, min(1.0, across / radius)))
        corrected.append(alpha % (2.0 * math.pi))
    return sorted(corrected)

"""Ahmadi & Stone's experiment: S-coverage of a biconnected team under random additions and
removals (Ahmadi & Stone, "Experimental Results").

Setting: every robot is responsible for a circular region of one size; at most
``MAX_ROBOTS`` = 10 robots, 5 at the start; each episode removes a random robot when there
are 10, adds one when there are none, and otherwise adds or removes with probability 1/2.
S-coverage = area of the union of the regions / sum of the region areas (exact,
:func:`algorithms.maintenance.regions.union_area`), measured after each episode's add or
remove has settled and averaged over the episodes with at least one robot.

"Region size" is ambiguous in the paper (radius or diameter). We read it as the
**diameter** D, and "neighbours" as the paper defines them, "can communicate from anywhere
in their assigned regions": with communication range cr * D, two regions are neighbours
iff their centres are at most ``(cr - 1) * D`` apart. Only this reading makes the paper's
remark true that at cr = 2 "only adjacent robot regions are considered neighbors" (centres
at most D apart: the discs touch or overlap). Reading size as the radius with the same
neighbour rule leaves no neighbours at all at cr = 2.

The robots hold at their region centres, so the simulated radio's range is that
guaranteed range ``(cr - 1) * D`` between robot positions: the radio graph is the region
neighbour graph the algorithms reason about, and the distributed check checks it.

Other choices: the team of 5 is built by five additions before the first episode (the
paper's step 3, construction from scratch, is future work there; the first robot holds at
the origin). An added robot enters 0.3 m from a uniformly chosen team member (at the
origin into an empty team), in a random direction; when that spot is closer than the
clearance to a robot on the floor (ground truth: the experimenter places it), the
direction turns in steps of 30 degrees, then the distance grows by 0.1 m, until it is
clear (no extra random draws, so both worlds see the same episodes). One control tick is
0.1 s.

Bodies: in the embodied world robots keep ``CLEARANCE_M`` = 0.25 m centre to centre
(chassis 0.15 m wide): they hold apart when region centres come closer
(:func:`algorithms.maintenance.regions.hold_points`) and drive around the hold points
they know (:func:`algorithms.maintenance.regions.path_around`); an episode has settled
when every robot is at its hold point. Points need no clearance (0), so the point world
runs the paper's algorithm unchanged. Coverage is always computed from the region
centres; the radio and the distributed check see where the robots really hold, so the
two worlds' coverages can differ after a removal.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass, field

import numpy as np

from algorithms.maintenance.biconnected import PLACEMENTS, BiconnectedRobot, Dismiss, Params
from algorithms.maintenance.regions import union_area
from mjswarm.errors import MjswarmError
from mjswarm.worlds.loop import Loop, LoopFunctions
from mjswarm.worlds.openfloor import EmbodiedFloor, MotionWorld, PointWorld
from mjswarm.core.radio import Radio

MAX_ROBOTS = 10
START_ROBOTS = 5
WORLDS = ("embodied", "point")
#: Largest region diameter D (m): the embodied floor reaches 3 (cr - 1) D per robot, up to
#: 900 m from the origin at cr 4, and MuJoCo loses millimetres beyond about a kilometre.
MAX_REGION_DIAMETER_M = 10.0
#: the paper's S-coverage means (percent) by (cr, placement)
PAPER_COVERAGE = {(2.0, "heuristic"): 73.0, (4.0, "heuristic"): 91.0,
                  (2.0, "min-intersection"): 75.0}
ENTRY_OFFSET_M = 0.3
#: centre-to-centre distance the embodied robots keep (m); points keep none
CLEARANCE_M = 0.25


@dataclass
class Episode:
    """One episode's outcome: what happened and the coverage after it settled."""

    index: int
    action: str                 #: "add" or "remove"
    robot: int                  #: the robot added or removed
    robots: int                 #: team size after the episode
    coverage: float | None      #: S-coverage (None for an empty team)
    ticks: int                  #: control ticks until settled
    messages: int               #: radio transmissions in the episode
    moves: int                  #: Move floods (removals)
    checks: int                 #: distributed checks run (removals)


@dataclass
class CoverageResult:
    cr: float
    placement: str
    world: str
    seed: int
    region_diameter_m: float
    link_m: float
    episodes: list[Episode] = field(default_factory=list)
    collisions: int | None = None
    sim_time_s: float = 0.0

    @property
    def mean_coverage(self) -> float:
        values = [e.coverage for e in self.episodes if e.coverage is not None]
        return float(np.mean(values)) if values else float("nan")

    def to_dict(self) -> dict:
        data = asdict(self)
        data["mean_coverage"] = self.mean_coverage
        data["paper_mean_coverage"] = (
            PAPER_COVERAGE.get((self.cr, self.placement), None))
        if data["paper_mean_coverage"] is not None:
            data["paper_mean_coverage"] /= 100.0
        return data


class CoverageRun(LoopFunctions):
    """The experiment's loop functions: world, radio, robots, episodes.

    One :class:`~mjswarm.worlds.loop.Loop` runs the :class:`BiconnectedRobot` controllers; this
    object adds and removes robots between episodes and stops the loop when an episode
    has settled.

    Args:
        cr: communication range / region diameter (> 1).
        placement: one of :data:`PLACEMENTS`.
        world: "point" or "embodied".
        seed: seeds the episode choices and the world.
        region_diameter_m: D, the diameter of every region (m).
        max_ticks: an episode that has not settled by then raises :class:`MjswarmError`.
        clearance_m: distance robots keep (m); default ``CLEARANCE_M`` embodied, 0 points.
        functions: more loop functions that watch the run (a recording, a video: the
            caller makes and closes them; the episodes reach them as
            :meth:`~mjswarm.worlds.loop.Loop.event` s), hooked in before the team is built.
    """

    def __init__(self, cr: float, placement: str = "heuristic", world: str = "point",
                 seed: int = 0, region_diameter_m: float = 1.0, max_ticks: int = 20_000,
                 clearance_m: float | None = None,
                 functions: Sequence[LoopFunctions] = ()) -> None:
        if not (math.isfinite(cr) and cr > 1.0):
            raise MjswarmError(f"cr must be a number above 1, got {cr}")
        if placement not in PLACEMENTS:
            raise MjswarmError(f"unknown placement {placement!r} (choose from "
                               f"{', '.join(PLACEMENTS)})")
        if world not in WORLDS:
            raise MjswarmError(f"unknown world {world!r} (choose from {', '.join(WORLDS)})")
        if not region_diameter_m > 0.2:
            raise MjswarmError("region diameter must exceed 0.2 m (a robot is 0.15 m wide)")
        if not region_diameter_m <= MAX_REGION_DIAMETER_M:
            raise MjswarmError(f"region diameter must be at most {MAX_REGION_DIAMETER_M:g} m "
                               "(the floor would reach beyond a kilometre)")
        self.cr, self.placement, self.world_name = float(cr), placement, world
        if clearance_m is None:
            clearance_m = CLEARANCE_M if world == "embodied" else 0.0
        if not (math.isfinite(clearance_m) and 0.0 <= clearance_m < region_diameter_m):
            raise MjswarmError(f"clearance must be in [0, region diameter), got {clearance_m}")
        from mjswarm.core.robot import spark_v_geometry  # loads MuJoCo

        self.params = Params(link_m=(cr - 1.0) * region_diameter_m,
                             region_radius_m=region_diameter_m / 2.0,
                             max_robots=MAX_ROBOTS, placement=placement,
                             v_max=spark_v_geometry().max_speed_m_s, clearance_m=clearance_m)
        self.rng = np.random.default_rng(seed)
        self.max_ticks = max_ticks
        self.coverage_result = CoverageResult(self.cr, placement, world, seed, region_diameter_m,
                                      self.params.link_m)
        starts = [(0.0, 0.0)] * MAX_ROBOTS
        absent = [False] * MAX_ROBOTS
        tick = self.params.tick_s
        self.world: MotionWorld
        if world == "point":
            self.world = PointWorld(starts, present=absent, seed=seed, control_dt_s=tick)
        else:
            half = max(10.0, 3.0 * MAX_ROBOTS * self.params.link_m)
            self.world = EmbodiedFloor(starts, present=absent, seed=seed,
                                       floor_half_size_m=half, control_dt_s=tick)
        self.world.attach_radio(Radio(range(MAX_ROBOTS), range_m=self.params.link_m))
        robots = {i: BiconnectedRobot(i, self.params) for i in range(MAX_ROBOTS)}
        self.loop = Loop(self.world, robots, [self, *functions])
        self._ticks, self._running = 0, ""
        for _ in range(START_ROBOTS):
            self._episode("add", -1)

    @property
    def team(self) -> list[int]:
        """The robots on the floor (the team), in id order."""
        return self.world.active()

    def _report(self, robot: int) -> dict:
        """What robot ``robot`` reports of itself (its telemetry)."""
        return self.loop.controllers[robot].telemetry()

    def _hold(self, robot: int) -> tuple[float, float]:
        """Where a robot of the team says it holds (m)."""
        report = self._report(robot)
        return report["hold_x_m"], report["hold_y_m"]

    # -- episodes -------------------------------------------------------------------------
    def step_episode(self) -> Episode:
        """One random add or remove, run until it has settled."""
        n = len(self.team)
        add = n == 0 or (n < MAX_ROBOTS and self.rng.random() < 0.5)
        episode = self._episode("add" if add else "remove", len(self.coverage_result.episodes))
        self.coverage_result.episodes.append(episode)
        return episode

    def run(self, episodes: int, progress: Callable[[], None] | None = None) -> CoverageResult:
        for _ in range(episodes):
            self.step_episode()
            if progress:
                progress()
        self.coverage_result.sim_time_s = self.world.time_s
        self.coverage_result.collisions = self.world.contacts
        return self.coverage_result

    def coverage(self) -> float | None:
        """S-coverage of the current regions (None for an empty team)."""
        reports = [self._report(k) for k in self.team]
        centres = [(t["region_x_m"], t["region_y_m"]) for t in reports]
        if not centres:
            return None
        r = self.params.region_radius_m
        return union_area(centres, r) / (len(centres) * math.pi * r * r)

    def _episode(self, action: str, index: int) -> Episode:
        world, radio = self.world, self.world.radio
        sent_before = radio.total_sent
        team = self.team
        led = {k: self._led(k) for k in team}  # the counts the episode adds to
        if action == "add":
            robot = min(set(range(MAX_ROBOTS)) - set(team))
            world.place(robot, self._entry_point(), float(self.rng.uniform(-math.pi, math.pi)))
        else:
            robot = int(self.rng.choice(team))
            if len(team) == 1:  # nobody to tell, nothing to repair
                world.place(robot, None)
                return Episode(index, action, robot, 0, None, 0, 0, 0, 0)
            # dismissed: its last broadcast, heard by its neighbours, then off the floor
            self.loop.last_words(robot, Dismiss())
            world.place(robot, None)
        self.loop.event(f"episode {index}: {action} R{robot + 1}", robot)
        self._ticks, self._running = 0, f"episode {index} ({action} robot {robot})"
        self.loop.run()
        gained = [(m - led.get(k, (0, 0))[0], c - led.get(k, (0, 0))[1])
                  for k in self.team for m, c in [self._led(k)]]
        return Episode(index, action, robot, len(self.team), self.coverage(), self._ticks,
                       radio.total_sent - sent_before, sum(m for m, _ in gained),
                       sum(c for _, c in gained))

    def _led(self, robot: int) -> tuple[int, int]:
        """The MOVE floods and distributed checks ``robot`` says it has led."""
        report = self._report(robot)
        return report["moves_led"], report["checks_led"]

    # -- loop-function hooks ----------------------------------------------------------------
    def after_step(self, loop: Loop) -> None:
        self._ticks += 1

    def should_stop(self, loop: Loop) -> bool:
        """The episode has settled: nothing sent in the tick, nobody busy, all holding."""
        if self._settled():
            return True
        if self._ticks >= self.max_ticks:
            raise MjswarmError(f"{self._running} did not settle within {self.max_ticks} ticks")
        return False

    def result(self, loop: Loop) -> CoverageResult:
        return self.coverage_result

    def _settled(self) -> bool:
        if self.world.radio.last_batch:
            return False
        reports = {k: self._report(k) for k in self.team}
        if any(t["busy"] for t in reports.values()):
            return False
        truth = self.world.true_positions()
        return all(math.dist(truth[k], (t["hold_x_m"], t["hold_y_m"])) <= self.params.tolerance_m
                   for k, t in reports.items())

    def _entry_point(self) -> tuple[float, float]:
        if not self.team:
            return 0.0, 0.0
        host = self._hold(int(self.rng.choice(self.team)))
        a = self.rng.uniform(-math.pi, math.pi)
        truth = self.world.true_positions()
        robots = [truth[k] for k in range(MAX_ROBOTS) if self.world.present[k]]
        offset = ENTRY_OFFSET_M
        while True:
            for turn in range(12):
                b = a + turn * math.pi / 6.0
                p = host[0] + offset * math.cos(b), host[1] + offset * math.sin(b)
                if all(math.dist(p, q) >= self.params.clearance_m for q in robots):
                    return p
            offset += 0.1


def area(cr: float, region_diameter_m: float = 1.0) -> tuple[float, float, float, float]:
    """The square (m) that recordings and videos frame: the team stays near the origin."""
    half = region_diameter_m * (cr + 1.0) / 2.0
    return (-half, -half, half, half)


def run_coverage(cr: float, placement: str = "heuristic", episodes: int = 100,
                 seed: int = 0, world: str = "embodied", region_diameter_m: float = 1.0,
                 progress: Callable[[], None] | None = None,
                 functions: Sequence[LoopFunctions] = ()) -> CoverageResult:
    """Build the team of 5 and run ``episodes`` random add / remove episodes, watched by
    ``functions`` (a recording, a video)."""
    if episodes < 1:
        raise MjswarmError(f"need at least one episode, got {episodes}")
    run = CoverageRun(cr, placement, world, seed, region_diameter_m, functions=functions)
    return run.run(episodes, progress)


__all__ = ["CoverageResult", "CoverageRun", "Episode", "run_coverage"]

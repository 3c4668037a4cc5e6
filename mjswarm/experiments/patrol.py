"""The patrol mission of Kobayashi, Higuchi & Ueno (Sect. IV-B) on our robots.

Robot 0 is the base station at the origin; robots 1..N-1 start at random in the fan
``||x|| <= 0.6 sqrt(N)`` m, x, y >= 0 (the quadrant of the targets), at least 0.2 m
apart and 0.2 m from the base station; the one closest to the base station is the local
leader, the rest explorers; the draw is repeated until the network (base station - local
leader link plus the Gabriel graph of the others within d_c) is connected. The base
station is given a target drawn in ``[0, 1.8 sqrt(N)]^2`` m and a new one as soon as it
hears the local leader's arrival (the experimenter sends targets as messages and learns
of arrivals from the base station's events: :mod:`.patrol_mission`, whose loop functions
also take the measurements below); the mission lasts ``steps`` timesteps of
``STEP_S`` = 0.15 s (1 paper unit = 1 m, so the paper's 0.03 unit/step cap is the Spark
V's 0.2 m/s).

Each step: the radio (:class:`mjswarm.core.radio.Radio`, range d_c) delivers last step's
messages, every robot reads its sensors (detection within d_s of the positioning-sensor
readings, with roles) and runs :class:`algorithms.maintenance.roles.RoleSwitchingRobot`,
and the world follows the velocities for one step. Metrics (ground truth, not seen by
the robots):

* the *network* is the graph of mutual connections (``j in A_i`` and ``i in A_j``) no
  longer than d_c; a *disconnection* is a maximal run of steps in which some robot is not
  connected to the base station, and its length is its recovery time (Fig. 7); a
  *leader gap* is such a run for the local leader alone;
* processing time: wall time of each robot's controller call, per robot per step (s);
* messages: copies received (radio counter) per robot per step;
* algebraic connectivity (networkx) of the network, sampled every ``sample_every`` steps;
* the AAT's cost as the robots ran it (``aat_robots``: Algorithm 2, or the baseline
  with ``every_step_aat``; their own counters and time, from their telemetry) and, on
  the same positions every step, the every-step baseline run in the shadow (not used for
  control), with the algebraic connectivity of the local-leader-and-explorer graph that
  each gives (Fig. 4, 5).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass, field

import networkx as nx
import numpy as np

from algorithms.maintenance.gabriel import gabriel_graph
from algorithms.maintenance.roles import Role, RoleParams, RoleSwitchingRobot, Target
from algorithms.robot import Command, Controller, Observation
from mjswarm.errors import MjswarmError
from mjswarm.experiments.patrol_mission import PatrolMission, draw_target, runs
from mjswarm.worlds.loop import Loop, LoopFunctions
from mjswarm.worlds.openfloor import EmbodiedFloor, MotionWorld, PointWorld
from mjswarm.core.radio import Radio

#: Duration of one paper timestep (s): 0.03 m/step = 0.2 m/s, 0.15 rad/step = 1 rad/s.
STEP_S = 0.15
#: Kobayashi et al.'s turn-rate cap, 0.15 rad per timestep (Sect. III-C).
PAPER_TURN_CAP_RAD_PER_STEP = 0.15
WORLDS = ("embodied", "point")
#: Fewest robots a patrol takes: the base station, the leader and one explorer.
MIN_ROBOTS = 3
#: Most robots a patrol takes: a step costs about N^2 (every pair's links, the AAT), and
#: 300 point robots already take about a second a step.
MAX_ROBOTS = 200


@dataclass
class TrialResult:
    """One mission. Times in seconds, lengths in metres, durations in steps."""

    robots: int
    steps: int
    seed: int
    world: str
    disconnections: int
    recovery_steps: list[int]
    leader_gaps: list[int]
    targets_reached: int
    repeaters_final: int
    processing_s_per_robot_step: float
    processing_s_per_robot_step_by_role: dict[str, float]
    messages_per_robot_step: float
    algebraic_connectivity: float
    aat_robots: dict[str, float]
    aat_every_step: dict[str, float]
    collisions: int | None
    wall_s: float
    history: dict[str, list] = field(default_factory=dict, repr=False)


def initial_positions(n: int, rng: np.random.Generator, params: RoleParams,
                      attempts: int = 1000) -> np.ndarray:
    """Draw the deployment of Sect. IV-B (see the module docstring); (N, 2) in metres."""
    if n < MIN_ROBOTS:
        raise MjswarmError(f"the patrol needs at least 3 robots (base station, leader, "
                           f"explorer), got {n}")
    radius = 0.6 * math.sqrt(n)
    for _ in range(attempts):
        points = [np.zeros(2)]
        while len(points) < n:
            for _ in range(10_000):
                r, a = radius * math.sqrt(rng.uniform()), rng.uniform(0.0, math.pi / 2)
                p = np.array([r * math.cos(a), r * math.sin(a)])
                if all(np.linalg.norm(p - q) >= 0.2 for q in points):
                    points.append(p)
                    break
            else:
                raise MjswarmError(f"cannot place {n} robots 0.2 m apart in the fan")
        xy = np.array(points)
        leader = 1 + int(np.argmin(np.linalg.norm(xy[1:], axis=1)))
        g = nx.Graph()
        g.add_nodes_from(range(n))
        g.add_edges_from((a + 1, b + 1) for a, b in map(tuple, gabriel_graph(xy[1:], params.d_c)))
        if np.linalg.norm(xy[leader]) <= params.d_c:
            g.add_edge(0, leader)
        if nx.is_connected(g):
            return xy
    raise MjswarmError(f"no connected deployment of {n} robots in {attempts} draws")


def make_world(kind: str, positions: np.ndarray, seed: int, d_s: float) -> MotionWorld:
    """The point world or the MuJoCo floor, sized for the target area, with a
    range-and-bearing sensor of range ``d_s`` (m)."""
    omega = PAPER_TURN_CAP_RAD_PER_STEP / STEP_S  # the paper's 0.15 rad/step
    points = [tuple(p) for p in positions]
    if kind == "point":
        return PointWorld(points, seed=seed, omega_max_rad_s=omega, control_dt_s=STEP_S,
                          detection_range_m=d_s)
    if kind == "embodied":
        half = 1.8 * math.sqrt(len(positions)) + 4.0
        return EmbodiedFloor(points, seed=seed, floor_half_size_m=half, omega_max_rad_s=omega,
                             control_dt_s=STEP_S, detection_range_m=d_s)
    raise MjswarmError(f"unknown world {kind!r} (choose from {', '.join(WORLDS)})")


class Timed(Controller):
    """A controller measured: wall time of its steps (s), in total and by the role the
    robot showed when the step began (the paper's processing time, Fig. 8-9); ``role``
    is the one it starts with."""

    def __init__(self, inner: Controller, role: Role) -> None:
        self.inner, self.role = inner, role
        self.seconds = 0.0
        self.by_role: dict[str, list[float]] = {}

    def reset(self) -> None:
        self.inner.reset()

    def step(self, observation: Observation) -> Command:
        t0 = time.perf_counter()
        command = self.inner.step(observation)
        elapsed = time.perf_counter() - t0
        self.seconds += elapsed
        spent = self.by_role.setdefault(self.role.value, [0.0, 0])
        spent[0] += elapsed
        spent[1] += 1
        if command.signal is not None:
            self.role = command.signal
        return command

    def telemetry(self):
        return self.inner.telemetry()


def deploy(xy: np.ndarray, params: RoleParams, first: Target,
           every_step_aat: bool) -> tuple[list[Role], dict[int, frozenset], list[Controller]]:
    """The experimenter builds the team on positions ``xy`` (m): robot 0 the base
    station with target ``first``, the robot nearest to it the local leader, linked to
    it, the rest explorers. Returns the roles, the initial connections and the robots."""
    n = len(xy)
    leader = 1 + int(np.argmin(np.linalg.norm(xy[1:], axis=1)))
    roles = [Role.BASE_STATION] + [Role.EXPLORER] * (n - 1)
    roles[leader] = Role.LOCAL_LEADER
    links = {0: frozenset({leader}), leader: frozenset({0})}
    minds: list[Controller] = [
        RoleSwitchingRobot(0, Role.BASE_STATION, params, child=leader, connections=links[0],
                           target=first, step_s=STEP_S)]
    for i in range(1, n):
        minds.append(RoleSwitchingRobot(i, roles[i], params, parent=0 if i == leader else None,
                                        connections=links.get(i, ()),
                                        every_step_aat=every_step_aat, step_s=STEP_S))
    return roles, links, minds


def run_trial(robots: int, seed: int, world: str = "point", steps: int = 2000,
              params: RoleParams | None = None, every_step_aat: bool = False,
              sample_every: int = 10, progress: Callable[[int], None] | None = None,
              keep_history: bool = False,
              functions: Sequence[LoopFunctions] = ()) -> TrialResult:
    """One patrol mission of ``steps`` timesteps with ``robots`` robots (base station
    included). ``every_step_aat`` drives the robots with the baseline instead of
    Algorithm 2; ``functions`` are more loop functions that watch the mission (a
    recording, a video: the caller makes them, hands them in and closes them)."""
    params = params or RoleParams()
    if steps < 1 or sample_every < 1:
        raise MjswarmError("steps and sample interval must be at least 1")
    started = time.perf_counter()
    rng = np.random.default_rng(seed)
    xy0 = initial_positions(robots, rng, params)
    first = draw_target(rng, robots, 0)
    roles, links, minds = deploy(xy0, params, first, every_step_aat)
    mission = PatrolMission(rng, params, roles, links, first, sample_every, keep_history,
                            progress)
    floor = make_world(world, xy0, seed, params.d_s)
    floor.attach_radio(Radio(range(robots), range_m=params.d_c, rng=seed))
    timed = [Timed(m, r) for m, r in zip(minds, roles)]
    loop = Loop(floor, dict(enumerate(timed)), [mission, *functions])
    loop.run(max_ticks=steps)
    robot_steps = robots * steps
    cpu_by_role: dict[str, list[float]] = {r.value: [0.0, 0] for r in Role}
    for t in timed:
        for role, (seconds, calls) in t.by_role.items():
            cpu_by_role[role][0] += seconds
            cpu_by_role[role][1] += calls
    final = [t.telemetry() for t in timed]  # the robots' AAT counters
    angle_alg2, circle_alg2 = (sum(f[k] for f in final) for k in ("angle_tests", "circle_tests"))
    shadow = mission.shadow
    return TrialResult(
        robots=robots, steps=steps, seed=seed, world=world,
        disconnections=len(runs(mission.cut)), recovery_steps=runs(mission.cut),
        leader_gaps=runs(mission.leader_cut), targets_reached=mission.targets,
        repeaters_final=sum(r is Role.REPEATER for r in floor.signals),
        processing_s_per_robot_step=float(sum(t.seconds for t in timed) / robot_steps),
        processing_s_per_robot_step_by_role={
            r: (s / k if k else None) for r, (s, k) in cpu_by_role.items()},
        messages_per_robot_step=sum(floor.radio.received.values()) / robot_steps,
        algebraic_connectivity=float(np.mean(mission.lam)),
        aat_robots={"angle_tests_per_robot_step": angle_alg2 / robot_steps,
                    "circle_tests_per_robot_step": circle_alg2 / robot_steps,
                    "tests_per_robot_step": (angle_alg2 + circle_alg2) / robot_steps,
                    "seconds_per_robot_step": sum(f["aat_s"] for f in final) / robot_steps,
                    "algebraic_connectivity": float(np.mean(mission.lam_alg2))},
        aat_every_step={"angle_tests_per_robot_step": shadow["angle_tests"] / robot_steps,
                        "seconds_per_robot_step": shadow["seconds"] / robot_steps,
                        "algebraic_connectivity": float(np.mean(mission.lam_base))},
        collisions=floor.contacts,
        wall_s=time.perf_counter() - started,
        history=mission.history if keep_history else {},
    )


def summarize(trials: list[TrialResult]) -> dict:
    """Means over trials (the paper's Fig. 4, 5, 7, 10, 11 quantities) plus the trials."""
    def mean(values):
        values = [v for v in values if v is not None]
        return float(np.mean(values)) if values else None

    recoveries = [np.mean(t.recovery_steps) for t in trials if t.recovery_steps]
    return {
        "robots": trials[0].robots,
        "trials": len(trials),
        "steps": trials[0].steps,
        "world": trials[0].world,
        "disconnections_per_trial": mean([t.disconnections for t in trials]),
        "mean_recovery_steps": mean(recoveries),
        "max_recovery_steps": max((max(t.recovery_steps) for t in trials if t.recovery_steps),
                                  default=0),
        "disconnected_steps_per_trial": mean([sum(t.recovery_steps) for t in trials]),
        "leader_gaps_per_trial": mean([len(t.leader_gaps) for t in trials]),
        "max_leader_gap_steps": max((max(t.leader_gaps) for t in trials if t.leader_gaps),
                                    default=0),
        "targets_per_trial": mean([t.targets_reached for t in trials]),
        "processing_s_per_robot_step": mean([t.processing_s_per_robot_step for t in trials]),
        "processing_s_per_robot_step_by_role": {
            r: mean([t.processing_s_per_robot_step_by_role[r] for t in trials])
            for r in trials[0].processing_s_per_robot_step_by_role},
        "messages_per_robot_step": mean([t.messages_per_robot_step for t in trials]),
        "algebraic_connectivity": mean([t.algebraic_connectivity for t in trials]),
        "aat_robots": {k: mean([t.aat_robots[k] for t in trials]) for k in trials[0].aat_robots},
        "aat_every_step": {k: mean([t.aat_every_step[k] for t in trials])
                           for k in trials[0].aat_every_step},
        "collisions_per_trial": mean([t.collisions for t in trials]),
        "wall_s": float(sum(t.wall_s for t in trials)),
        "per_trial": [{k: v for k, v in asdict(t).items() if k != "history"} for t in trials],
    }


def area(robots: int) -> tuple[float, float, float, float]:
    """The target square (m), which recordings and videos frame."""
    side = 1.8 * math.sqrt(robots)
    return (0.0, 0.0, side, side)


def run_patrol(robots: int, trials: int = 1, seed: int = 0, world: str = "embodied",
               steps: int = 2000, params: RoleParams | None = None,
               every_step_aat: bool = False,
               progress: Callable[[int], None] | None = None,
               functions: Sequence[LoopFunctions] = ()) -> dict:
    """``trials`` missions (seeds ``seed .. seed + trials - 1``), summarised; with
    ``functions`` (loop functions that watch a mission: a recording, a video), of the
    single mission."""
    if trials < 1:
        raise MjswarmError(f"need at least one trial, got {trials}")
    if world not in WORLDS:
        raise MjswarmError(f"unknown world {world!r} (choose from {', '.join(WORLDS)})")
    if functions and trials != 1:
        raise MjswarmError(f"a recording or video holds one mission; got {trials} trials")
    results = [run_trial(robots, seed + k, world, steps, params, every_step_aat,
                         progress=progress, functions=functions) for k in range(trials)]
    return summarize(results)
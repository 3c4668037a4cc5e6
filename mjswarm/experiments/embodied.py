"""An embodied exploration run's parameters (:class:`EmbodiedConfig`), its result
(:class:`EmbodiedResult`) and the constants of its loop functions (SI units)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from algorithms.collision import PAPER_SPEED_M_S, epsilons
from mjswarm.arena import ArenaSpec
from mjswarm.arena.geometry import LANE_OFFSET_M
from mjswarm.core.robot import spark_v_geometry
from mjswarm.errors import MjswarmError
from mjswarm.experiments.faults import Fault, check_fault
from mjswarm.experiments.radio_exploration import CONNECTIVITY, need_robots
from mjswarm.experiments.results import ExplorationResult

#: The tether's leash keeps parents within the radio range less this (m): a control
#: period's drive at top speed (4 mm), turns and the one-tick-old ranging, with room.
TETHER_MARGIN_M = 0.02
#: Of the leash, what only a walk back may use (m, the tether's ``reserve_m``): a U-turn
#: sidesteps two lane offsets across its edge, with room for the odometry's back-up to
#: where its lane ended.
TURN_RESERVE_M = 2 * LANE_OFFSET_M + 0.02
#: What pictures of a run say the marked vertices are.
BEACON_LABEL = "beacon dropped (vertex explored)"
#: Default stall timeout: at least this long (s), and at least STALL_EDGE_FACTOR times
#: the time to drive the longest edge at the run's speed.
STALL_MIN_S = 300.0
STALL_EDGE_FACTOR = 10.0


@dataclass
class EmbodiedConfig:
    """Parameters of an embodied run (SI units).

    Attributes:
        speed_m_s: the initial speed S of every robot (Nagavarapu et al.'s experiments: 0.05).
        collision_avoidance: the speed rule and vertex entry (see module doc).
        epsilons: per-robot eps_k (eq. 28); default :func:`algorithms.collision.epsilons`.
        launch_interval_s: least time between two launches from the root.
        launch_order: robot indices in launch order (default 0, 1, ...).
        idle_wait_s: how long a robot whose strategy answered IDLE waits before asking again.
        max_sim_time_s: give up after this much simulated time.
        stall_timeout_s: end the run early when no robot has reached a vertex for this
            long (s); None: ``max(STALL_MIN_S, STALL_EDGE_FACTOR * longest edge / speed)``.
        turn_rate_rad_s: in-place turn and scan rate.
        bearing_fov_deg, bearing_range_m, bearing_noise_deg: the bearing sensor.
        radio_range_m: with a range (m), robots carry radios and keep connectivity tables
            (:mod:`mjswarm.experiments.awareness`); None: no radio.
        faults: injected faults (:mod:`mjswarm.experiments.faults`).
        line_noise_m, ir_noise_m: standard deviation of the line and IR rangefinders'
            Gaussian noise (m).
        wheel_slip: scale of the wheel-slip model (:class:`mjswarm.core.simulation.Simulation`).
        physics: ``"dynamic"`` (MuJoCo's contact physics) or ``"kinematic"`` (the fast
            tier, :mod:`mjswarm.core.kinematic`).
        expected_edge_m: the edge length the robots are told to expect (m): with
            ``connectivity``, a time unit of the tether's waits (rules 5 and 6) is this
            edge at ``speed_m_s`` plus a scan. None: the arena's mean edge, which the
            experimenter knows and tells the robots (a stated assumption, as the speed
            is; the robots never measure the arena for it).
        connectivity: ``"none"``, ``"connected"`` or ``"biconnected"`` (both need
            ``radio_range_m``): every robot keeps its tether of one or two parents to a
            base station at the root (:mod:`algorithms.exploration.tether`; see the
            module docstring); with ``"biconnected"`` the first robot in
            ``launch_order`` docks at the base (rule 1) and is never launched.
    """

    speed_m_s: float = PAPER_SPEED_M_S
    collision_avoidance: bool = True
    epsilons: list[float] | None = None
    launch_interval_s: float = 2.0
    launch_order: list[int] | None = None
    idle_wait_s: float = 2.0
    max_sim_time_s: float = 3600.0
    stall_timeout_s: float | None = None
    turn_rate_rad_s: float = 1.0
    bearing_fov_deg: float = 60.0
    bearing_range_m: float = 1.0
    bearing_noise_deg: float = 0.0
    radio_range_m: float | None = None
    faults: list[Fault] = field(default_factory=list)
    line_noise_m: float = 0.0
    ir_noise_m: float = 0.0
    wheel_slip: float = 0.0
    physics: str = "dynamic"
    connectivity: str = "none"
    expected_edge_m: float | None = None


@dataclass
class EmbodiedResult(ExplorationResult):
    """An embodied run's measurements: the graph world's keys plus physics ones.

    ``edge_time`` is ``"physics"``; ``makespan`` counts edges (see the module docstring).
    Robots are numbered from 1 (R1 is 1) in ``stopped_robots``.
    """

    collisions: int = 0
    speed_changes: int = 0
    sim_time_s: float = 0.0
    wall_time_s: float = 0.0
    realtime_factor: float = 0.0
    #: why the run ended: "completed", "completed reachable part" (closed vertices, see
    #: ``unreachable_edges``), "stalled", "all robots stopped", "max time",
    #: "interrupted" (Ctrl-C; what was measured until then) or the infeasibility verdict
    ended_because: str = ""
    #: robots that stopped for good: ``{"robot": R, "reason": ..., "at_s": t}``
    stopped_robots: list[dict] = field(default_factory=list)
    #: largest |odometry heading - true heading| of any robot over the run (deg), on lanes
    #: and at vertex calls
    heading_error_deg: float = 0.0
    #: injected faults and when they took effect: ``{"fault": text, "fired": True,
    #: "at_s": t}``; a fault whose time the run did not reach has ``"fired": False`` and
    #: ``"at_s": None``
    faults: list[dict] = field(default_factory=list)
    #: with a radio: messages sent in all, by the busiest robot, and the share of sampled
    #: robot beliefs ("biconnected" or not) that equalled the truth
    radio_messages: int | None = None
    radio_max_messages_per_robot: int | None = None
    radio_belief_agreement: float | None = None
    #: vertex-entry messages between robots and stations, both ways
    #: (:mod:`algorithms.exploration.entry`)
    station_messages: int = 0
    #: requests dropped because their robot gave up its place in a queue and planned
    #: round that edge (:mod:`algorithms.exploration.entry`, step 8)
    queue_give_ups: int = 0
    #: the connectivity constraint, and the ground truth on it: ticks (with a robot on the
    #: floor) in which some robot had no radio route to the base, or the radio graph with
    #: the base was not biconnected, and their shares
    connectivity: str = "none"
    cut_ticks: int = 0
    fragile_ticks: int = 0
    connected_share: float | None = None
    biconnected_share: float | None = None
    #: the robots declared a stall (rule 5 of the tether): ``infeasible`` with fewer
    #: robots than the arena needs (``robots_needed``,
    #: :func:`~mjswarm.experiments.reach.robots_needed`), else ``stalled``
    infeasible: bool = False
    stalled: bool = False
    robots_needed: int | None = None
    reason: str | None = None
    #: relay missions the robots set out on (rule 6 of :mod:`algorithms.exploration.relay`)
    relay_trips: int = 0
    #: vertices closed by a body stopped for good in their area:
    #: ``{"vertex": v, "robot": R, "at_s": t}``, and every true edge outside the part
    #: reachable from the root without entering one, and not in the declared map:
    #: ``{"edge": [u, v], "why": text}`` (:func:`mjswarm.experiments.metrics.
    #: reachable_part`). A declaration that leaves such edges is a completion of the
    #: reachable part (``ended_because``: "completed reachable part"); with closed
    #: vertices ``map_correct`` says the map holds every edge of that part and only true
    #: edges (edges mapped before their vertex closed may be in it too).
    closed_vertices: list[dict] = field(default_factory=list)
    unreachable_edges: list[dict] = field(default_factory=list)
    #: robots cut off from the root that finished the part they could reach (``CUT_OFF``):
    #: ``{"robot": R, "vertex": v, "at_s": t}``. When every robot left is cut off (or
    #: cannot be launched: the root closed), nobody declares; the run is the team's
    #: completion of the reachable part, its map the union of their maps
    #: (:func:`mjswarm.experiments.metrics.team_cut_off`), and
    #: ``declared_by`` is None.
    cut_off_robots: list[dict] = field(default_factory=list)


def same_lane_bearing(range_m: float) -> float:
    """The ``|beta|`` (rad) below which the speed rule takes a robot for one ahead on the
    same lane (eq. (27), ``beta = 0``): half the bearing, at the sensor's full range, of a
    robot on the edge's centre line, ``atan(LANE_OFFSET_M / 2 / range)`` (2.6 degrees at
    1 m). Robots on vertex centres stand on centre lines; one waiting on the centre of the
    vertex beyond the one a robot drives to (vertex entry) is no obstacle, and stopping
    for it would wait for ever (``arena2`` with 4 robots: a robot waiting on v9 for v5
    would stop the robot driving from v3 to v5). A robot on the opposite lane is
    twice as far off again. The rule gets its bearings in the lane's frame (the
    navigator's ``lane_bearings``: bearing + heading - lane direction), so a nose turned a
    few degrees off the lane does not bring such a robot into the cone."""
    return math.atan2(LANE_OFFSET_M / 2.0, range_m)


def check_config(spec: ArenaSpec, k: int, config: EmbodiedConfig) -> list[int]:
    """Refuse, in one line, a parameter that does not fit; the launch order."""
    if config.speed_m_s <= 0:
        raise MjswarmError(f"speed must be positive, got {config.speed_m_s} m/s")
    order = list(range(k)) if config.launch_order is None else list(config.launch_order)
    if sorted(order) != list(range(k)):
        raise MjswarmError(f"launch order must be a permutation of 0..{k - 1}, got {order}")
    if config.stall_timeout_s is not None and not config.stall_timeout_s > 0:
        raise MjswarmError(f"stall timeout must be positive, got {config.stall_timeout_s} s")
    if len(config.epsilons or epsilons(k)) != k:
        raise MjswarmError(f"need {k} epsilons, got {len(config.epsilons)}")
    if config.radio_range_m is not None and not config.radio_range_m > 0:
        raise MjswarmError(f"radio range must be positive, got {config.radio_range_m} m")
    if config.connectivity not in CONNECTIVITY:
        raise MjswarmError(f"connectivity must be one of {', '.join(CONNECTIVITY)}, "
                           f"got '{config.connectivity}'")
    if config.connectivity != "none" and config.radio_range_m is None:
        raise MjswarmError(f"connectivity {config.connectivity} needs a radio range")
    need_robots(config.connectivity, k)
    for fault in config.faults:
        check_fault(fault, k, spec, config.radio_range_m is not None, config.max_sim_time_s)
    top = spark_v_geometry().max_speed_m_s
    if config.speed_m_s > top:
        raise MjswarmError(f"speed {config.speed_m_s} m/s exceeds the robot's top speed "
                           f"{top:.2f} m/s")
    return order


def stall_timeout(spec: ArenaSpec, config: EmbodiedConfig) -> float:
    """The run's stall timeout (s): the configured one, or at least ``STALL_MIN_S`` and
    ``STALL_EDGE_FACTOR`` times the time to drive the longest edge."""
    if config.stall_timeout_s is not None:
        return config.stall_timeout_s
    longest = max(math.dist(spec.vertices[u], spec.vertices[v]) for u, v in spec.edges)
    return max(STALL_MIN_S, STALL_EDGE_FACTOR * longest / config.speed_m_s)


def tether_unit_ticks(spec: ArenaSpec, config: EmbodiedConfig, control_dt_s: float) -> int:
    """Control ticks in a time unit of the tether's waits (rules 5 and 6): what the graph
    world's edge stands for, the edge the robots expect (``config.expected_edge_m``; by
    default the arena's mean edge, told to the robots) at the run's speed, and the scan at
    the vertex it leads to (one full turn)."""
    edge_m = config.expected_edge_m
    if edge_m is None:
        edge_m = float(np.mean([math.dist(spec.vertices[u], spec.vertices[v])
                                for u, v in spec.edges]))
    unit_s = edge_m / config.speed_m_s + 2.0 * math.pi / config.turn_rate_rad_s
    return max(1, round(unit_s / control_dt_s))

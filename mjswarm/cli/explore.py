"""``mjswarm explore``: run one exploration and report Nagavarapu et al.'s metrics.

Worlds: ``embodied`` (MuJoCo robots with their own sensors, :mod:`mjswarm.experiments.exploration`; the
default) and ``graph`` (the fast abstract graph world, :mod:`mjswarm.worlds.graphworld`). Each
world is a function ``run_<world>(args) -> dict`` registered in :data:`WORLDS`.
"""

from __future__ import annotations

from contextlib import ExitStack

from algorithms.collision import PAPER_SPEED_M_S
from algorithms.exploration import STRATEGIES
from mjswarm.cli.numbers import number, whole
from mjswarm.cli.output import (
    atomic_output,
    check_outputs,
    check_writable,
    drop_if_useless,
    interrupted_outputs,
    write_json,
)
from mjswarm.cli.video_options import add_video_options, check_video
from mjswarm.core import PHYSICS
from mjswarm.core.radio import MAX_RANGE_M
from mjswarm.errors import MjswarmError, RunInterrupted
from mjswarm.experiments.radio_exploration import CONNECTIVITY
from mjswarm.worlds.graphworld import EDGE_TIMES


def run_graph(args) -> dict:
    """One run in the graph world; the JSON-ready result (see ``ExplorationResult``).
    With ``--record``, a recording on the time-unit timeline
    (:class:`~mjswarm.outputs.exploration_recording.GraphExplorationRecording`)."""
    from mjswarm.experiments.runs import run_exploration

    spec = _spec(args)
    with ExitStack() as outputs:
        functions = []
        if args.record:
            from mjswarm.outputs.exploration_recording import GraphExplorationRecording
            from mjswarm.outputs.recording import Recorder

            temp = outputs.enter_context(atomic_output(args.record, "recording"))
            recorder = outputs.enter_context(Recorder(
                temp, spec, args.robots, radio=args.radio_range is not None, sensors=False,
                name=f"{spec.name}, {args.robots} robots, graph world", trail_window_s=5.0))
            functions.append(GraphExplorationRecording(recorder, spec))
        result = run_exploration(spec, args.robots, args.strategy, world="graph",
                                 seed=args.seed, max_time=args.max_time,
                                 edge_time=args.edge_time or "unit",
                                 radio_range_m=args.radio_range,
                                 connectivity=args.connectivity, functions=functions,
                                 radio_walls=args.radio_model != "open")
    radio = {"radio_model": args.radio_model or "walls"} if args.radio_range else {}
    return {"world": "graph", **result.to_dict(), **radio,
            **({"recording": args.record} if args.record else {})}


def _spec(args):
    """The arena, from its root or ``--root``."""
    from mjswarm.arena import ArenaSpec, load_arena

    spec = load_arena(args.arena)
    if args.root and args.root != spec.root:
        spec = ArenaSpec(spec.name, args.root, spec.vertices, spec.edges, spec.description,
                         spec.source)
    return spec


def run_embodied(args) -> dict:
    """One run with MuJoCo robots; the JSON-ready result (see ``EmbodiedResult``).

    Every option is checked before any output file is opened; the recording and the
    video go to temporary files that replace ``--record`` and ``--video`` when the run
    ends, or vanish if the run is refused (:func:`mjswarm.cli.output.atomic_output`)."""
    from mjswarm.experiments.exploration import EmbodiedConfig
    from mjswarm.experiments.faults import parse_fault
    from mjswarm.experiments.runs import run_exploration
    from mjswarm.experiments.awareness import truth
    from mjswarm.outputs.exploration_recording import ExplorationRecording
    from mjswarm.outputs.recording import Recorder
    from mjswarm.outputs.video import Video, area, filming

    spec = _spec(args)
    defaults = EmbodiedConfig()
    config = EmbodiedConfig(
        speed_m_s=_or(args.speed, defaults.speed_m_s),
        collision_avoidance=not args.no_collision_avoidance,
        launch_interval_s=_or(args.launch_interval, defaults.launch_interval_s),
        launch_order=launch_order(args.launch_order, args.robots),
        stall_timeout_s=args.stall_timeout,
        faults=[parse_fault(f) for f in args.fault or ()],
        line_noise_m=_or(args.line_noise, 0.0), ir_noise_m=_or(args.ir_noise, 0.0),
        wheel_slip=_or(args.wheel_slip, 0.0), physics=args.physics or defaults.physics,
        bearing_noise_deg=_or(args.bearing_noise, defaults.bearing_noise_deg))
    with ExitStack() as outputs:
        recorder = video = None
        if args.record:
            temp = outputs.enter_context(atomic_output(args.record, "recording"))
            recorder = Recorder(temp, spec, args.robots, radio=args.radio_range is not None,
                                video=args.video is not None)
            outputs.push(drop_if_useless(temp, lambda: recorder.ticks > 0))
            outputs.enter_context(recorder)
        recording = None if recorder is None else ExplorationRecording(recorder, spec, truth)
        if args.video:
            video = Video(outputs.enter_context(atomic_output(args.video, "video")),
                          area(spec.vertices.values()), check_video(args),
                          title=f"{spec.name}, {args.robots} robots")
        with filming(video, recorder):
            try:
                result = run_exploration(
                    spec, args.robots, args.strategy, world="embodied", seed=args.seed,
                    max_time=args.max_time, radio_range_m=args.radio_range,
                    connectivity=args.connectivity, config=config,
                    functions=[f for f in (recording, video) if f is not None], progress=True)
            except RunInterrupted as stop:  # the outputs keep their partial contents
                stop.result = _embodied_dict(stop.result, args)
                raise
    return _embodied_dict(result, args)


def _embodied_dict(result, args) -> dict:
    """An embodied run's JSON-ready result, with where its outputs went."""
    return {"world": "embodied", **result.to_dict(), "recording": args.record,
            "video": args.video}


def launch_order(text: str | None, k: int) -> list[int] | None:
    """``--launch-order 3,1,2`` as 0-based robot indices; one line, in R1..RK numbers,
    if it is not an order of all K robots."""
    if not text:
        return None
    try:
        numbers = [int(x) for x in text.split(",")]
    except ValueError:
        raise MjswarmError(f"--launch-order takes robot numbers like 2,1,3, "
                           f"got '{text}'") from None
    if sorted(numbers) != list(range(1, k + 1)):
        raise MjswarmError(f"--launch-order must name each of R1..R{k} once (robot numbers "
                           f"1..{k}, e.g. {','.join(map(str, range(k, 0, -1)))}), got {text}")
    return [n - 1 for n in numbers]


def _or(value, default):
    """``value`` unless the option was not given (None)."""
    return default if value is None else value


#: Teams up to this size have their traversals listed robot by robot in the summary.
SUMMARY_ROBOTS = 20
#: World name -> runner.
WORLDS = {"embodied": run_embodied, "graph": run_graph}


def register(subparsers) -> None:
    parser = subparsers.add_parser(
        "explore",
        help="explore an arena with K robots and report makespan, traversals and the map",
        description=(
            "Explore an arena from its root with K robots running one strategy and report "
            "the metrics of Nagavarapu, Vachhani & Sinha's incidence-matrix exploration: "
            "makespan (time steps until a robot declares completion; "
            "with unit edge time, the paper's number of edge traversals), total and "
            "per-robot traversals, who declared where, and the declaring robot's map; "
            "embodied runs add collisions, speed changes and simulated/wall time. "
            "Exit status 1 if no robot declared completion before --max-time."
        ),
    )
    parser.add_argument("--world", default="embodied", metavar="WORLD",
                        help=f"simulation world: {', '.join(WORLDS)} (default: embodied, "
                             "MuJoCo robots; graph: the abstract graph world, no physics)")
    parser.add_argument("--arena", required=True, metavar="ARENA",
                        help="shipped arena name (e.g. fig9, tree1, arena2), path to a "
                             ".json/.toml spec, or generator (lattice:RxC, "
                             "random-tree:E:SEED, random-graph:V:E:SEED, fan:N:DEG, wheel:N, "
                             "hex:RxC, tri:RxC, random-planar:V:SEED); append @DEG to rotate "
                             "it about its root")
    parser.add_argument("--robots", action=whole(), required=True, metavar="K",
                        help="number of robots, all starting at the root")
    parser.add_argument("--strategy", default="incidence-dfs", metavar="NAME",
                        help=f"one of {', '.join(STRATEGIES)} (default: incidence-dfs, "
                             "Nagavarapu et al.'s incidence-matrix method)")
    parser.add_argument("--root", default=None, metavar="VERTEX",
                        help="start vertex (default: the arena's root)")
    parser.add_argument("--seed", action=whole(least=0), default=None, metavar="S",
                        help="randomise tie-breaking with this seed (default: the "
                             "strategies' fixed tie rules)")
    parser.add_argument("--connectivity", default=None, choices=CONNECTIVITY,
                        help="none: explore as Nagavarapu et al. do, unconstrained "
                             "(default); connected: every robot "
                             "keeps a radio route to the base at the root; biconnected: two "
                             "disjoint routes, so that one robot failing cuts nobody off "
                             "(the first robot docks at the base as its partner and does "
                             "not explore; needs 2 or more robots). "
                             "Needs --radio-range. A team that cannot go on says so "
                             "(infeasible: fewer robots than the arena needs; else "
                             "stalled) and stops. Robots stuck at the end of their "
                             "leash call relays, in both worlds")
    parser.add_argument("--radio-range", default=None, metavar="M",
                        action=number(above=0, most=MAX_RANGE_M,
                                      why="m; a longer range reaches no further in any arena"),
                        help="radio range, m. Graph world: robots and a base at the root "
                             "talk within it where the arena's walls do not come between "
                             "them (--radio-model), and the result reports "
                             "messages and the share of time every robot had a route to "
                             "the base. Embodied world: walls block; the robots keep "
                             "Le et al.'s connectivity tables while they move and the result "
                             "reports how often their beliefs matched the truth; with "
                             "--connectivity they keep their tether to a base on a 1 m mast "
                             "at the root instead")
    parser.add_argument("--max-time", action=number(above=0), default=None, metavar="T",
                        help="give up after T: graph world time units (default: "
                             "50 (E + 1) + 100); embodied simulated seconds (default: 3600)")
    graph = parser.add_argument_group("graph world")
    graph.add_argument("--radio-model", default=None, choices=("walls", "open"),
                       help="with --radio-range: 'walls' (default): a link needs line of "
                            "sight past the arena's walls, the base's antenna on its 1 m "
                            "mast, as on the MuJoCo robots; 'open': range alone")
    graph.add_argument("--edge-time", default=None, choices=EDGE_TIMES,
                       help="time to traverse an edge: 'unit' (1 step each, as in the "
                            "paper) or 'length' (length / mean edge length) (default: unit)")
    embodied = parser.add_argument_group("embodied world")
    embodied.add_argument("--speed", action=number(above=0), default=None, metavar="M_S",
                          help=f"initial speed S of every robot, m/s (default: "
                               f"{PAPER_SPEED_M_S:g}, the paper's experiments; at most the "
                               "robot model's top speed)")
    embodied.add_argument("--no-collision-avoidance", action="store_true",
                          help="turn off the bearing-rate speed rule and the vertex-entry "
                               "check, for comparison")
    embodied.add_argument("--launch-interval", action=number(least=0), default=None,
                          metavar="S",
                          help="least time between two robots leaving the root, seconds "
                               "(default: 2)")
    embodied.add_argument("--launch-order", default=None, metavar="I,J,...",
                          help="order in which robots R1..RK are put on the root, e.g. "
                               "3,1,2 (default: 1,2,...)")
    embodied.add_argument("--stall-timeout", action=number(above=0), default=None,
                          metavar="S",
                          help="end the run, not completed, when no robot has reached a vertex "
                               "for S simulated seconds (default: 300 s, or 10x the time to "
                               "drive the longest edge if that is longer)")
    embodied.add_argument("--fault", action="append", default=None, metavar="FAULT",
                          help="inject a fault (repeatable): robot:I@T (robot I fails at T s "
                               "and stays as an obstacle), beacon:V@T (the beacon at vertex V "
                               "is wiped), radio-blackout@T1-T2 (no radio message gets "
                               "through; needs --radio-range)")
    embodied.add_argument("--line-noise", action=number(least=0), default=None, metavar="M",
                          help="standard deviation of the line sensors' noise, m (default: 0)")
    embodied.add_argument("--ir-noise", action=number(least=0), default=None, metavar="M",
                          help="standard deviation of the IR sensors' noise, m (default: 0)")
    embodied.add_argument("--wheel-slip", action=number(least=0), default=None, metavar="S",
                          help="wheel slip: each tick each encoder over-reads its wheel's "
                               "turn by |N(0, S)| of it (default: 0)")
    embodied.add_argument("--bearing-noise", action=number(least=0), default=None,
                          metavar="DEG",
                          help="standard deviation of the bearing sensor's noise, degrees "
                               "(default: 0)")
    embodied.add_argument("--physics", choices=PHYSICS, default=None,
                          help="dynamic: MuJoCo's contact physics (default); kinematic: "
                               "robots move by their wheel kinematics and stop at contacts, "
                               "same scene and sensors, several times faster at large teams")
    parser.add_argument("--record", default=None, metavar="FILE.rrd",
                        help="write a rerun recording of the run, in any world (open it "
                             "with `mjswarm view FILE.rrd`)")
    add_video_options(embodied)
    parser.add_argument("--json", default=None, metavar="PATH|-",
                        help="write the result as JSON to PATH, or to stdout with '-'")
    parser.set_defaults(func=run)


#: Options of the embodied world only (argparse dest -> flag), refused with --world graph.
EMBODIED_ONLY = {
    "speed": "--speed", "no_collision_avoidance": "--no-collision-avoidance",
    "launch_interval": "--launch-interval", "launch_order": "--launch-order",
    "stall_timeout": "--stall-timeout", "fault": "--fault",
    "line_noise": "--line-noise", "ir_noise": "--ir-noise", "wheel_slip": "--wheel-slip",
    "bearing_noise": "--bearing-noise",
    "physics": "--physics", "video": "--video", "video_speed": "--video-speed",
}


def check_options(args) -> None:
    """Refuse what would be silently ignored or is impossible, in one line."""
    if args.world not in WORLDS:
        raise MjswarmError(f"unknown world '{args.world}' (choose from {', '.join(WORLDS)})")
    if args.world == "graph":
        given = [flag for dest, flag in EMBODIED_ONLY.items() if getattr(args, dest)]
        if given:
            raise MjswarmError(f"{', '.join(given)} "
                               f"{'applies' if len(given) == 1 else 'apply'} only to the "
                               "embodied world (--world embodied)")
    else:
        given = [flag for flag, value in (("--edge-time", args.edge_time),
                                          ("--radio-model", args.radio_model)) if value]
        if given:
            raise MjswarmError(f"{', '.join(given)} {'applies' if len(given) == 1 else 'apply'}"
                               " only to the graph world (--world graph)")
    if args.radio_model is not None and args.radio_range is None:
        raise MjswarmError("--radio-model needs --radio-range")
    if args.connectivity not in (None, "none"):
        if args.radio_range is None:
            raise MjswarmError(f"--connectivity {args.connectivity} needs --radio-range")
    if args.launch_order:
        launch_order(args.launch_order, args.robots)
    check_writable(args.json, "JSON")
    check_outputs({"--record": args.record, "--video": args.video, "--json": args.json},
                  {"--record": ".rrd"})
    check_video(args)


def run(args) -> int:
    check_options(args)
    try:
        result = WORLDS[args.world](args)
    except RunInterrupted as stop:  # say what is known, then exit as interrupted
        for key in ("recording", "video"):  # where the partial went, if anywhere
            if stop.result.get(key):
                stop.result[key] = interrupted_outputs.get(stop.result[key])
        report(stop.result, args, partial=True)
        raise
    report(result, args)
    return 0 if result["completed"] else 1


def report(result: dict, args, partial: bool = False) -> None:
    """The result to ``--json`` and the summary to stdout (unless the JSON went there)."""
    if not write_json(result, args.json, partial):
        print(summary(result))


def summary(result: dict) -> str:
    """Human-readable lines for one run, the same for every ending."""
    head = (f"{result['arena']}: {result['robots']} robot(s), {result['strategy']}, "
            f"{result['world']} world, root {result['root']}")
    traversals = f"traversals: {result['total_traversals']} in total " \
                 f"({per_robot(result['traversals_per_robot'])})"
    unreachable = result.get("unreachable_edges") or []
    if result["completed"] and unreachable:  # closed vertices: the part it could reach
        verdict = "covering" if result["map_correct"] else "NOT covering"
        cut = ", ".join(f"R{c['robot']} at {c['vertex']}"
                        for c in result.get("cut_off_robots") or [])
        if result["declared_by"] is not None:
            by = f"R{result['declared_by']} declared completion at {result['declared_at']}"
        elif cut:  # the team's verdict: nobody could declare
            by = f"every robot left is cut off from the root and finished its part ({cut})"
        else:
            by = "no robot was out when the root closed"
        lines = [head,
                 f"completed the reachable part: {by}; makespan {result['makespan']:g} "
                 "edges (most by any robot)",
                 traversals,
                 f"map: {len(result['map_edges'])} edges, {verdict} the reachable part "
                 f"({len(unreachable)} of the arena's edges unreachable)"]
    elif result["completed"]:
        verdict = "equal to" if result["map_correct"] else "DIFFERENT from"
        unit = "edges (most by any robot)" if result["world"] == "embodied" else "steps"
        lines = [head,
                 f"completed: R{result['declared_by']} declared completion at "
                 f"{result['declared_at']}; makespan {result['makespan']:g} {unit}",
                 traversals,
                 f"map: {len(result['map_edges'])} edges, {verdict} the arena's"]
    else:
        why = result.get("reason") or result.get("ended_because") or "max time"
        lines = [head, f"not completed ({why}): no robot declared completion", traversals]
        if result.get("infeasible"):
            lines.append(f"infeasible: the team stalled (the tether's rule 5), and a robot "
                         f"at the farthest point of an edge needs a chain of "
                         f"{result['robots_needed']} robots to the base at this range; add "
                         f"robots or range")
        elif result.get("stalled"):
            needed = result["robots_needed"]
            lines.append(f"stalled: no robot reached a new vertex for a while (the "
                         f"tether's rule 5), though {needed} robot{'s' * (needed != 1)} could "
                         f"reach every edge at this range: the team did not find the way "
                         f"(its relays could not get where they were needed); a longer "
                         f"range needs fewer relays")
    if "radio_range_m" in result:
        lines.append(
            f"radio {result['radio_range_m']:g} m"
            f"{' (walls block)' if result.get('radio_model') == 'walls' else ''}"
            f"{' (range alone)' if result.get('radio_model') == 'open' else ''}, "
            f"connectivity {result['connectivity']}: "
            f"{result['messages']} messages, {result['relay_trips']} relay "
            f"trip{'s' * (result['relay_trips'] != 1)}; every "
            f"robot reached the base in {100 * result['connected_share']:.1f} % of the "
            f"ticks, the team with the base was biconnected in "
            f"{100 * result['biconnected_share']:.1f} %")
    if result["world"] == "embodied":
        lines += _embodied_lines(result)
    elif result.get("recording"):
        lines.append(f"recording: {result['recording']}")
    return "\n".join(lines)


def per_robot(counts: list[int], listed: int = SUMMARY_ROBOTS) -> str:
    """``R1=5 R2=3 ...``, or for a team larger than ``listed`` the spread."""
    if len(counts) <= listed:
        return " ".join(f"R{i + 1}={n}" for i, n in enumerate(counts))
    return (f"R1..R{len(counts)}: {min(counts)} to {max(counts)} each, "
            f"mean {sum(counts) / len(counts):.1f}")


def _embodied_lines(result: dict) -> list[str]:
    """The summary lines of the physics: time, contacts, stops, faults, radio, outputs."""
    end = result["sim_time_s"]
    lines = [
        (f"physics: {end:.1f} s simulated in {result['wall_time_s']:.1f} s "
         f"({result['realtime_factor']:.1f}x real time)"),
        (f"collisions: {result['collisions']} robot-robot contact events; "
         f"speed changes (eq. 27): {result['speed_changes']}"),
        (f"vertex entry: {result['station_messages']} messages with the stations, "
         f"{result['queue_give_ups']} places in a queue given up"),
    ]
    lines += [f"stopped: R{s['robot']} at {s['at_s']:.1f} s: {s['reason']}"
              for s in result["stopped_robots"]]
    lines += [f"unreachable: {'-'.join(e['edge'])}: {e['why']}"
              for e in result.get("unreachable_edges", [])]
    lines += [f"fault: {f['fault']} at {f['at_s']:.1f} s" if f["fired"] else
              f"fault: {f['fault']} not fired (the run ended at {end:.1f} s)"
              for f in result["faults"]]
    if result["connectivity"] != "none" and result["connected_share"] is not None:
        trips = result["relay_trips"]
        lines.append(
            f"connectivity {result['connectivity']}: {trips} relay trip{'s' * (trips != 1)}; "
            f"every robot reached the base in {100 * result['connected_share']:.1f} % of "
            f"the ticks ({result['cut_ticks']} cut), biconnected in "
            f"{100 * result['biconnected_share']:.1f} %")
    if result["radio_messages"] is not None:
        agreement = result["radio_belief_agreement"]
        lines.append(
            f"radio: {result['radio_messages']} messages (busiest robot "
            f"{result['radio_max_messages_per_robot']})" + (
                "" if agreement is None  # no connectivity tables in tethered runs
                else f"; beliefs matched the truth in {100 * agreement:.1f} % of samples"))
    if result["recording"]:
        lines.append(f"recording: {result['recording']}")
    if result["video"]:
        lines.append(f"video: {result['video']}")
    return lines

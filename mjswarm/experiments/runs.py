"""One entry point for an exploration run in any world: :func:`run_exploration`.

The CLI (``mjswarm explore``), sweeps, benchmarks and users' scripts all run
explorations through it:

* ``world="graph"``: the synchronous graph world (:mod:`mjswarm.experiments.
  graph_exploration`); with ``radio_range_m``, the graph world with a radio and a base
  (:mod:`mjswarm.experiments.radio_exploration`);
* ``world="embodied"``: Spark V robots in MuJoCo (:mod:`mjswarm.experiments.exploration`),
  with ``config`` for the physics, sensors and faults.

The strategy runs inside a controller in each world; the result is an
:class:`~mjswarm.experiments.results.ExplorationResult` (or its embodied or connected
extension).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace

from mjswarm.arena import ArenaSpec
from mjswarm.errors import MjswarmError
from mjswarm.experiments.minds import StrategyFactory, make_minds
from mjswarm.experiments.results import ExplorationResult
from mjswarm.worlds.loop import LoopFunctions

#: The worlds :func:`run_exploration` runs.
WORLDS = ("graph", "embodied")


def run_exploration(spec: ArenaSpec, robots: int,
                    strategy: str | StrategyFactory = "incidence-dfs", *,
                    world: str = "graph", seed: int | None = None,
                    max_time: float | None = None, edge_time: str = "unit",
                    radio_range_m: float | None = None, connectivity: str | None = None,
                    config=None, functions: Sequence[LoopFunctions] = (),
                    progress: bool = False, radio_walls: bool = True) -> ExplorationResult:
    """Explore ``spec`` from its root with ``robots`` robots running ``strategy`` (a
    name from ``STRATEGIES`` or a factory) in ``world``.

    ``max_time``: graph time units, or embodied simulated seconds (default: each world's);
    ``edge_time``: the graph world's edge durations; ``radio_range_m`` and
    ``connectivity``: a radio, and the constraint to keep; ``config``: the embodied run's
    :class:`~mjswarm.experiments.exploration.EmbodiedConfig` (its radio, constraint and
    time limit are set from the arguments above when given); ``functions``: more loop
    functions that watch the run (a recording, e.g. :class:`~mjswarm.outputs.
    exploration_recording.ExplorationRecording`, a video); ``progress``: a progress display (embodied world);
    ``radio_walls``: in the graph world, the arena's walls block radio links as they do
    the MuJoCo robots' (False: the open model, range alone; the embodied world's walls
    always block).
    """
    if world not in WORLDS:
        raise MjswarmError(f"unknown world '{world}' (choose from {', '.join(WORLDS)})")
    if world == "embodied":
        from mjswarm.experiments.exploration import EmbodiedConfig, explore_embodied

        config = config or EmbodiedConfig()
        config = replace(
            config, connectivity=connectivity or config.connectivity,
            radio_range_m=config.radio_range_m if radio_range_m is None else radio_range_m,
            max_sim_time_s=config.max_sim_time_s if max_time is None else max_time)
        return explore_embodied(spec, robots, strategy, config, seed, functions, progress)
    minds = make_minds(strategy, robots, seed)
    from mjswarm.worlds.graphworld import GraphWorld

    # loop functions that read the robots' VertexCalled reports (a recording) say so
    report = any(getattr(f, "reads_vertex_calls", False) for f in functions)
    graph = GraphWorld(spec.graph(), spec.root, edge_time=edge_time)
    if radio_range_m is None:
        from mjswarm.experiments.graph_exploration import run_minds

        return run_minds(graph, minds, seed=seed, max_time=max_time, arena=spec.name,
                         functions=functions, report=report)
    from mjswarm.experiments.radio_exploration import run_connected

    from mjswarm.arena.geometry import corridor_walls

    return run_connected(graph, minds, radio_range_m, connectivity or "none", seed=seed,
                         max_time=max_time, arena=spec.name, functions=functions,
                         report=report, walls=corridor_walls(spec) if radio_walls else None)

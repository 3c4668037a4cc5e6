"""The radio graph world's line of sight against walls (mjswarm.worlds.wall_sight) answers
as the MuJoCo robots' radio does, and keeps connected exploration's promise."""

from __future__ import annotations

import numpy as np
import pytest

from algorithms.exploration.tether import BASE
from mjswarm.arena import load_arena
from mjswarm.arena.builder import arena_world_spec
from mjswarm.arena.geometry import (LANE_OFFSET_M, WALL_HEIGHT_M, WALL_THICKNESS_M,
                                    corridor_walls)
from mjswarm.core.radio import ANTENNA_HEIGHT_M, BASE_MAST_M, FADE_MARGIN_M, sight_blocker
from mjswarm.core.simulation import Simulation
from mjswarm.core.world import Pose2D
from mjswarm.experiments.minds import make_minds
from mjswarm.experiments.radio_exploration import run_connected
from mjswarm.worlds.graphworld import GraphWorld
from mjswarm.worlds.wall_sight import wall_blocker


def on_edges(spec, rng, n: int) -> np.ndarray:
    """``n`` points on the arena's edges' centre lines (where the graph world's robots
    travel), m."""
    edges = [spec.edges[k] for k in rng.integers(len(spec.edges), size=n)]
    t = rng.random(n)[:, None]
    a = np.array([spec.vertices[u] for u, _ in edges])
    b = np.array([spec.vertices[v] for _, v in edges])
    return a + t * (b - a)


@pytest.mark.parametrize("arena", ["arena2", "hex:2x2"])
def test_walls_block_the_links_mujoco_blocks(arena):
    """Two MuJoCo robots put down at random points of the edges (at least two body
    diameters apart) hear each other exactly when the wall sight says they do, and the
    base's mast sees a robot exactly when MuJoCo's ray from the mast does."""
    spec, rng = load_arena(arena), np.random.default_rng(0)
    sim = Simulation(arena_world_spec(spec, [Pose2D(9.0, 9.0), Pose2D(-9.0, -9.0)]))
    mujoco_cut, root = sight_blocker(sim), spec.vertices[spec.root]
    walls, where = corridor_walls(spec), {}
    ours = wall_blocker(walls, where, {BASE: BASE_MAST_M})
    points, agree, blocked = on_edges(spec, rng, 240).reshape(-1, 2, 2), 0, 0
    for p, q in points:
        if np.hypot(*(p - q)) < 0.3:
            continue
        sim.place_robot(0, Pose2D(*p))
        sim.place_robot(1, Pose2D(*q))
        where.update({0: p, 1: q, BASE: root})
        theirs = bool(mujoco_cut(np.array([[0, 1]]))[0])
        assert bool(ours(np.array([[0, 1]], object))[0]) == theirs, (p, q)
        mast = not sim.sight.from_point(root, [0], BASE_MAST_M)[0]
        assert bool(ours(np.array([[BASE, 0]], object))[0]) == mast, p
        agree, blocked = agree + 1, blocked + theirs + mast
    assert agree > 80 and 0 < blocked < 2 * agree  # both answers occur


def test_two_fixed_nodes_always_link_and_an_open_line_is_never_blocked():
    spec = load_arena("arena2")
    walls = corridor_walls(spec)
    root = spec.vertices[spec.root]
    where = {BASE: root, 0: root, 1: spec.vertices["v2"]}
    cut = wall_blocker(walls, where, {BASE: BASE_MAST_M, 0: BASE_MAST_M})
    assert not cut(np.array([[BASE, 0]], object)).any()
    assert not wall_blocker([], where, {})(np.array([[0, 1]], object)).any()


def test_the_wall_aware_graph_world_keeps_every_robot_connected():
    """With walls a connected team retraces a step that a wall cut (as the MuJoCo robots
    do), so every robot keeps its route to the base in every tick; the walls cost it
    relay trips and time against the open model."""
    spec = load_arena("arena2")
    world = GraphWorld(spec.graph(), spec.root)
    walled = run_connected(world, make_minds("incidence-dfs", 4), 1.5, "connected",
                           walls=corridor_walls(spec))
    open_ = run_connected(world, make_minds("incidence-dfs", 4), 1.5, "connected")
    assert walled.completed and walled.map_correct and walled.connected_share == 1.0
    assert walled.relay_trips > open_.relay_trips and walled.makespan > open_.makespan


def clearance(walls, a: np.ndarray, b: np.ndarray) -> float:
    """Brute force: the least distance (m) between the segment ``a -> b`` (3-D, sampled
    every millimetre or so) and any wall's box."""
    points = a + np.linspace(0.0, 1.0, 2000)[:, None] * (b - a)
    best = np.inf
    for wall in walls:
        s, e = np.asarray(wall.start, float), np.asarray(wall.end, float)
        length = np.hypot(*(e - s))
        along, normal = (e - s) / length, np.array([-(e - s)[1], (e - s)[0]]) / length
        rel = points[:, :2] - (s + e) / 2.0
        dx = np.maximum(np.abs(rel @ along) - length / 2.0, 0.0)
        dy = np.maximum(np.abs(rel @ normal) - WALL_THICKNESS_M / 2.0, 0.0)
        dz = np.maximum(points[:, 2] - WALL_HEIGHT_M, 0.0)
        best = min(best, float(np.sqrt(dx**2 + dy**2 + dz**2).min()))
    return best


def test_a_link_fades_when_its_line_passes_near_a_wall():
    """The fading blocker (walls grown by ``FADE_MARGIN_M``) against a brute-force
    clearance, on random pairs of points on the lanes and from the base's mast: a link
    that fades passes within the margin of a wall (the grown box's corners reach
    sqrt(3) margins), one that does not fade clears every wall by the margin, and every
    cut link fades."""
    spec, rng = load_arena("hex:2x2"), np.random.default_rng(1)
    walls, where = corridor_walls(spec), {}
    masts = {BASE: BASE_MAST_M}
    cut = wall_blocker(walls, where, masts)
    fades = wall_blocker(walls, where, masts, grow_m=FADE_MARGIN_M)
    points = on_edges(spec, rng, 300) + rng.uniform(-LANE_OFFSET_M, LANE_OFFSET_M, (300, 2))
    root, seen = np.array(spec.vertices[spec.root], float), {True: 0, False: 0}
    for p, q in points.reshape(-1, 2, 2):
        where.update({0: p, 1: q, BASE: root})
        for pair, a, b in (([0, 1], (*p, ANTENNA_HEIGHT_M), (*q, ANTENNA_HEIGHT_M)),
                           ([BASE, 0], (*root, BASE_MAST_M), (*p, ANTENNA_HEIGHT_M))):
            pair = np.array([pair], object)
            faded, gap = bool(fades(pair)[0]), clearance(walls, np.array(a), np.array(b))
            assert not cut(pair)[0] or faded
            assert (gap <= FADE_MARGIN_M * 3 ** 0.5 + 1e-3) if faded else (gap >= FADE_MARGIN_M - 1e-3)
            seen[faded and not cut(pair)[0]] += 1
    assert seen[True] > 5 and seen[False] > 50  # both answers occur


def test_ground_truth_counts_the_links_walls_block():
    """The graph world's ground truth asks the walls too: an unconstrained team on arena2
    is cut off from the base in more ticks when walls block links than by range alone,
    and a connected team with walls never is (its links fade a step before a wall)."""
    spec = load_arena("arena2")
    world = GraphWorld(spec.graph(), spec.root)

    def cut(connectivity: str, walls) -> int:
        return run_connected(world, make_minds("incidence-dfs", 4), 1.5, connectivity,
                             walls=walls, max_time=60).cut_ticks

    walls = corridor_walls(spec)
    assert cut("none", walls) > cut("none", None) > 0
    assert cut("connected", walls) == 0


def test_the_fade_over_a_wall_top_is_set_apart():
    """``grow_top_m`` grows the walls in height only: links between robots (antennas below
    the walls' tops) fade the same whatever it is; lines from the mast fade less with a
    lower top, and some fade only with the full margin."""
    spec, rng = load_arena("arena2"), np.random.default_rng(2)
    walls, where = corridor_walls(spec), {}
    masts = {BASE: BASE_MAST_M}
    full = wall_blocker(walls, where, masts, grow_m=0.05)
    low = wall_blocker(walls, where, masts, grow_m=0.05, grow_top_m=0.0)
    points = on_edges(spec, rng, 400) + rng.uniform(-LANE_OFFSET_M, LANE_OFFSET_M, (400, 2))
    root, only_full = spec.vertices[spec.root], 0
    for p, q in points.reshape(-1, 2, 2):
        where.update({0: p, 1: q, BASE: root})
        robots, mast = np.array([[0, 1]], object), np.array([[BASE, 0]], object)
        assert full(robots)[0] == low(robots)[0]
        assert full(mast)[0] or not low(mast)[0]
        only_full += bool(full(mast)[0] and not low(mast)[0])
    assert only_full > 0

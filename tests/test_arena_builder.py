"""Arena spec -> MuJoCo world: every shipped arena builds, loads in plain MuJoCo, and
shows the robots what the paper's arenas showed theirs."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

from mjswarm.arena import lane_strips, load_arena, shipped_arenas
from mjswarm.arena.builder import VERTEX_SITE_PREFIX, arena_world_spec, export_mjcf
from mjswarm.cli import main
from mjswarm.core.simulation import Simulation
from mjswarm.core.world import Pose2D

ARENAS = [*shipped_arenas(), "lattice:4x4", "lattice:10x10"]


@pytest.mark.parametrize("name", ARENAS)
def test_export_loads_in_plain_mujoco(tmp_path, name):
    spec = load_arena(name)
    path = export_mjcf(spec, tmp_path / "arena.xml")
    model = mujoco.MjModel.from_xml_path(str(path))
    names = [model.geom(i).name for i in range(model.ngeom)]
    e = len(spec.edges)
    assert sum(n.startswith("strip") for n in names) == 4 * e  # 2 lanes + 2 spokes per edge
    assert sum(n.startswith("wall") for n in names) == 2 * e
    sites = {model.site(i).name for i in range(model.nsite)}
    assert sites == {VERTEX_SITE_PREFIX + v for v in spec.vertices}
    strips = [i for i, n in enumerate(names) if n.startswith("strip")]
    assert (model.geom_contype[strips] == 0).all() and (model.geom_conaffinity[strips] == 0).all()


def test_cli_export_with_robots(tmp_path, capsys):
    out = tmp_path / "fig9.xml"
    assert main(["arena", "export", "fig9", str(out), "--robots", "2"]) == 0
    model = mujoco.MjModel.from_xml_path(str(out))
    assert model.nu == 4 and model.nsensor == 20


def test_cli_export_of_a_bad_spec_writes_nothing(tmp_path, capsys):
    bad = tmp_path / "bad.json"
    bad.write_text('{"name": "bad", "vertices": {"a": [0, 0], "b": [1, 0]}, '
                   '"edges": [["a", "c"]]}')
    out = tmp_path / "out.xml"
    assert main(["arena", "export", str(bad), str(out)]) == 2
    assert not out.exists()
    assert len(capsys.readouterr().err.strip().splitlines()) == 1


@pytest.mark.parametrize("name", ["arena1", "arena2", "fig9"])
def test_ir_sees_walls_on_edges_and_none_at_vertices(name):
    """Robots on every lane's midpoint see their left wall; robots on every vertex centre,
    in every direction, see nothing (Nagavarapu et al. Sec. 5: vertex = absence of obstacles)."""
    spec = load_arena(name)
    on_lanes = []
    for strip in lane_strips(spec):
        (x0, y0), (x1, y1) = strip.start, strip.end
        on_lanes.append(Pose2D((x0 + x1) / 2, (y0 + y1) / 2, math.atan2(y1 - y0, x1 - x0)))
    # one robot per vertex (vertices are >= 0.5 m apart), one world per heading
    at_vertices = [[Pose2D(x, y, k * math.pi / 4) for x, y in spec.vertices.values()]
                   for k in range(8)]
    worlds = [(on_lanes, True)] + [(poses, False) for poses in at_vertices]
    for poses, expect_left_wall in worlds:
        sim = Simulation(arena_world_spec(spec, poses))
        sim.step(5)
        ir = sim.readings()["ir"]
        if expect_left_wall:
            assert np.isfinite(ir[:, 0]).all()
            assert np.all((ir[:, 0] > 0.01) & (ir[:, 0] < 0.05))
        else:
            assert np.isnan(ir).all()

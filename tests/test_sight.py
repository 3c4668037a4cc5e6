"""Line of sight by MuJoCo (``mj_ray`` / ``mj_multiRay``, sensing "mujoco") equals line of
sight by the grid caster (sensing "grid") on random scenes, pair by pair."""

from __future__ import annotations

import numpy as np
import pytest

from mjswarm.core import sight as sight_module
from mjswarm.core.bearing import BearingSensor
from test_raycast import arena_sims, random_state


@pytest.mark.parametrize("seed", range(4))
@pytest.mark.parametrize("multi_from", [1, 8, 10**6])  # always mj_multiRay, mixed, never
def test_mujoco_sight_equals_grid_sight(monkeypatch, seed, multi_from):
    monkeypatch.setattr(sight_module, "MULTI_RAY_FROM", multi_from)
    grid, mj = arena_sims(20)
    rng = np.random.default_rng(seed)
    state = random_state(grid, rng, tipped=0.1 * (seed % 2))
    grid.set_state(*state)
    mj.set_state(*state)
    assert grid.sensing == "grid" and mj.sensing == "mujoco"
    k, p = np.nonzero(~np.eye(grid.n, dtype=bool))
    order = rng.permutation(len(k))  # origins interleaved
    k, p = k[order], p[order]
    seen = mj.sight(k, p)
    assert np.array_equal(seen, grid.sight(k, p))
    assert seen.any() and not seen.all()
    point = (0.2, -0.4)
    assert np.array_equal(mj.sight.from_point(point, np.arange(mj.n), 0.3),
                          grid.sight.from_point(point, np.arange(grid.n), 0.3))
    assert BearingSensor(mj).read() == BearingSensor(grid).read()
    assert mj._rays is None  # MuJoCo's sensing never builds the grid caster for sight

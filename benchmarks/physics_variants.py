"""Bare ``mj_step`` speed of the bench world under physics variants.

Answers "how fast could the physics itself go?" for N robots driving straight:

* ``base``: the shipped model and options (cylinder wheels, 2 ms, Newton, pyramidal cones,
  one constraint solve per island);
* ``islands-off``: one monolithic constraint solve (``mjDSBL_ISLAND``);
* ``threadpool``: the shipped options with MuJoCo's thread pool of 2 workers;
* ``4ms``: a 4 ms timestep;
* ``ellipsoid``: wheels as thin ellipsoids (one floor contact each instead of two);
* ``ellipsoid+4ms+cg``: ellipsoid wheels, 4 ms, the CG solver and elliptic cones;
* ``ellipsoid+4ms+cg+islands-off``: the same with one monolithic solve.

Prints real-time factor, milliseconds per physics step, contacts per robot and mean speed
per variant. None of these is shipped (``docs/performance.md`` says why): ``islands-off``
changes multi-robot trajectories (no longer bit-identical), so every embodied figure
would need re-measuring, and the faster ones make the navigator's odometry drift past the bounds of
``tests/test_navigation.py``.

    python benchmarks/physics_variants.py --robots 1000
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

import mujoco
import numpy as np

from mjswarm.experiments.bench import BENCH_SPEED_M_S
from mjswarm.worlds.bench import bench_world
from mjswarm.core.robot import DEFAULT_ROBOT_XML

CYLINDER_WHEEL = '<geom type="cylinder" size="0.025 0.006" mass="0.03"'
ELLIPSOID_WHEEL = '<geom type="ellipsoid" size="0.025 0.025 0.006" mass="0.03"'
ISLAND_OFF = int(mujoco.mjtDisableBit.mjDSBL_ISLAND)
#: variant -> (ellipsoid wheels, timestep s, CG solver and elliptic cones, islands off,
#: thread-pool workers)
VARIANTS = {
    "base": (False, 0.002, False, False, 0),
    "islands-off": (False, 0.002, False, True, 0),
    "threadpool": (False, 0.002, False, False, 2),
    "4ms": (False, 0.004, False, False, 0),
    "ellipsoid": (True, 0.002, False, False, 0),
    "ellipsoid+4ms+cg": (True, 0.004, True, False, 0),
    "ellipsoid+4ms+cg+islands-off": (True, 0.004, True, True, 0),
}


def measure(n: int, variant: str, seconds: float) -> dict:
    ellipsoid, timestep, cg, islands_off, workers = VARIANTS[variant]
    xml = Path(DEFAULT_ROBOT_XML).read_text()
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "spark_v.xml"
        path.write_text(xml.replace(CYLINDER_WHEEL, ELLIPSOID_WHEEL) if ellipsoid else xml)
        sim = bench_world(n, robot_xml=str(path), sensing="mujoco")
    m, d = sim.model, sim.data
    m.opt.timestep = timestep
    if cg:
        m.opt.solver = mujoco.mjtSolver.mjSOL_CG
        m.opt.cone = mujoco.mjtCone.mjCONE_ELLIPTIC
    if islands_off:
        m.opt.disableflags |= ISLAND_OFF
    m.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_SENSOR)
    if workers:
        mujoco.mju_threadpool(d, workers)
    sim.set_velocity(np.full(n, BENCH_SPEED_M_S), np.zeros(n))
    mujoco.mj_step(m, d, nstep=50)
    steps = round(seconds / m.opt.timestep)
    start_xy = sim.poses()[:, :2].copy()
    start = time.perf_counter()
    mujoco.mj_step(m, d, nstep=steps)
    wall = time.perf_counter() - start
    speed = np.linalg.norm(sim.poses()[:, :2] - start_xy, axis=1).mean() / (steps * m.opt.timestep)
    return {"variant": variant, "robots": n, "realtime_factor": steps * m.opt.timestep / wall,
            "ms_per_step": 1e3 * wall / steps, "contacts_per_robot": d.ncon / n,
            "mean_speed_m_s": speed}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--robots", type=int, default=1000, help="robot count (default 1000)")
    parser.add_argument("--seconds", type=float, default=0.5, help="simulated seconds (default 0.5)")
    args = parser.parse_args()
    print(f"{'variant':>29} {'realtime':>9} {'ms/step':>8} {'contacts/robot':>15} {'speed m/s':>10}")
    for variant in VARIANTS:
        r = measure(args.robots, variant, args.seconds)
        print(f"{variant:>29} {r['realtime_factor']:>8.2f}x {r['ms_per_step']:>8.2f} "
              f"{r['contacts_per_robot']:>15.1f} {r['mean_speed_m_s']:>10.4f}")


if __name__ == "__main__":
    main()

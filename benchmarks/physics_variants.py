"""Bare ``mj_step`` speed of the bench world under physics variants (issue 8).

Answers "how fast could the physics itself go?" for N robots driving straight:

* ``base``: the shipped model and options (cylinder wheels, 2 ms, Newton, pyramidal cones);
* ``ellipsoid``: wheels as thin ellipsoids (one floor contact each instead of two);
* ``ellipsoid+4ms+cg``: also a 4 ms timestep, the CG solver and elliptic cones.

Prints real-time factor, contacts and mean speed per variant. These variants are NOT
shipped: with them the navigator's odometry heading drifts about 1.2 degrees per leg and
``tests/test_navigation.py`` fails (see README, "Benchmark").

    python benchmarks/physics_variants.py --robots 1000
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

import mujoco
import numpy as np

from mjswarm.bench import BENCH_SPEED_M_S, bench_world
from mjswarm.robot import DEFAULT_ROBOT_XML

CYLINDER_WHEEL = '<geom type="cylinder" size="0.025 0.006" mass="0.03"'
ELLIPSOID_WHEEL = '<geom type="ellipsoid" size="0.025 0.025 0.006" mass="0.03"'
VARIANTS = ("base", "ellipsoid", "ellipsoid+4ms+cg")


def measure(n: int, variant: str, seconds: float) -> dict:
    xml = Path(DEFAULT_ROBOT_XML).read_text()
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "spark_v.xml"
        path.write_text(xml if variant == "base" else xml.replace(CYLINDER_WHEEL, ELLIPSOID_WHEEL))
        sim = bench_world(n, robot_xml=str(path), sensing="mujoco")
    m, d = sim.model, sim.data
    if variant == "ellipsoid+4ms+cg":
        m.opt.timestep = 0.004
        m.opt.solver = mujoco.mjtSolver.mjSOL_CG
        m.opt.cone = mujoco.mjtCone.mjCONE_ELLIPTIC
    m.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_SENSOR)
    sim.set_velocity(np.full(n, BENCH_SPEED_M_S), np.zeros(n))
    mujoco.mj_step(m, d, nstep=50)
    steps = round(seconds / m.opt.timestep)
    start_xy = sim.poses()[:, :2].copy()
    start = time.perf_counter()
    mujoco.mj_step(m, d, nstep=steps)
    wall = time.perf_counter() - start
    speed = np.linalg.norm(sim.poses()[:, :2] - start_xy, axis=1).mean() / (steps * m.opt.timestep)
    return {"variant": variant, "robots": n, "realtime_factor": steps * m.opt.timestep / wall,
            "contacts_per_robot": d.ncon / n, "mean_speed_m_s": speed}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--robots", type=int, default=1000, help="robot count (default 1000)")
    parser.add_argument("--seconds", type=float, default=0.5, help="simulated seconds (default 0.5)")
    args = parser.parse_args()
    print(f"{'variant':>18} {'realtime':>9} {'contacts/robot':>15} {'speed m/s':>10}")
    for variant in VARIANTS:
        r = measure(args.robots, variant, args.seconds)
        print(f"{variant:>18} {r['realtime_factor']:>8.2f}x {r['contacts_per_robot']:>15.1f} "
              f"{r['mean_speed_m_s']:>10.4f}")


if __name__ == "__main__":
    main()

"""How long robots wait on vertex centres for the stations' grants, in one exploration.

Runs ``mjswarm explore`` with the given arguments and records, for every grant of a
request made from a vertex centre, the simulated time from the request to the grant
(the waits that :data:`algorithms.exploration.entry.GIVE_UP_S` is set against), then
prints their percentiles and how many reach 30, 60 and 120 s.

    python benchmarks/grant_waits.py --arena arena2 --robots 4
    python benchmarks/grant_waits.py --arena lattice:6x6 --robots 8 --speed 0.15 --seed 1
"""

from __future__ import annotations

import sys
from pathlib import Path

if __package__ in (None, ""):  # run as a script: make the repository importable
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import numpy as np  # noqa: E402

from mjswarm.cli import main  # noqa: E402
from algorithms.exploration import entry  # noqa: E402
from mjswarm.experiments import stations  # noqa: E402


def record_waits() -> list[float]:
    """Patch the stations so that every grant from a centre appends its wait (s)."""
    waits: list[float] = []
    grant, before_step = entry.VertexStations.grant, stations.StationService.before_step
    clock = {"now_s": 0.0}

    def timed_before_step(self, loop):
        clock["now_s"] = self.world.time_s
        return before_step(self, loop)

    def timed_grant(self):
        asked = dict(self.requests)
        granted = grant(self)
        waits.extend(clock["now_s"] - asked[r].since_s for r, _ in granted
                     if asked[r].at is not None)
        return granted

    stations.StationService.before_step = timed_before_step
    entry.VertexStations.grant = timed_grant
    return waits


if __name__ == "__main__":
    waits = record_waits()
    code = main(["explore", *sys.argv[1:]])
    if not waits:
        print("no grants from vertex centres")
        sys.exit(code)
    w = np.array(waits)
    p50, p90, p99 = np.percentile(w, [50, 90, 99])
    print(f"grants from centres: {len(w)}; wait (s) median {p50:.1f}, 90th {p90:.1f}, "
          f"99th {p99:.1f}, longest {w.max():.1f}; "
          f"at least 30 / 60 / 120 s: {(w >= 30).sum()} / {(w >= 60).sum()} / {(w >= 120).sum()}")
    sys.exit(code)

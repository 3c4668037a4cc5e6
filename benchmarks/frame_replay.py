"""Record a run's re-anchoring inputs once, then replay heading-fusion rules offline.

Analysis tool of issue 27's frame-fusion prototype (it reads the controllers' and the
world's state, as a metric does; no robot ever sees any of it). Re-anchoring rotates a
robot's odometry heading and the angles it measured together, so every motion it makes is
the same whatever its frame's offset: a rule for re-anchoring changes no trajectory, only
the heading's label (the main-job digest shows it). So one run, recorded with the old
rule (full adoption), gives every rule's heading error: at each vertex call the heading
offset from the recorded run shifts the measured angles, and a dropped beacon's stored
angles by its dropper's offset then.

    python benchmarks/frame_replay.py record --arena hex:3x3 --robots 3 --speed 0.15 \
        --wheel-slip 0.05 --physics kinematic --seed 1 --out run.pkl
    python benchmarks/frame_replay.py replay run.pkl [more.pkl ...] [--rules adopt,B]

Rules: ``adopt`` (the old re-anchoring), ``A``/``A1`` (robot-side fusion, every call /
once per scan), ``B`` (what :func:`~algorithms.navigation.navigator.fuse_frames` does:
robot and beacon offset both updated, once per scan), ``Bq*``/``BR*`` (its slip and scan
variances halved or doubled), ``C`` (B, but a robot back at the beacon it last fused with
corrects only its drift since), ``BL*`` (B plus a lane-end correction towards the
departure angle, over the lane's last N aligned headings or all). On issue 27's 22 slip
runs (the 8-run ablation, seeds 5-8 of it, ``hex:2x2@30`` dynamic seeds 0-2, every noise
on ``arena2`` and ``lattice:4x4@33``): adopt 5.48 mean / 8.87 worst / 8 of 22 within 5
degrees; B 4.58 / 7.51 / 16; halving or doubling its variances 4.53-4.70; C the same as
B; BL 4.41 / 7.66 / 17 (the lane drifts only 0.75 degrees rms per edge, the departure
spoke's own error is about as large). Replays of the recorded rule and of B agree with
the CLI's ``heading_error_deg`` to 0.01 degrees.
"""

from __future__ import annotations

import argparse
import math
import pickle
import sys
from pathlib import Path

if __package__ in (None, ""):
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from algorithms.navigation.motions import wrap
from algorithms.navigation.navigator import SCAN_FRAME_VAR, frame_offset


def record(args) -> None:
    from algorithms.exploration.explorer import Explorer
    from algorithms.navigation.navigator import Navigator
    from mjswarm.arena import load_arena
    from mjswarm.experiments.exploration import EmbodiedConfig
    from mjswarm.experiments.metrics import ExplorationMetrics
    from mjswarm.experiments.runs import run_exploration

    calls: list[dict] = []
    samples: dict[tuple[int, int], list[float]] = {}  # (robot, calls done) -> [min, max]
    Navigator.fuses_frames = property(lambda self: False)  # the old rule: full adoption

    reanchor = Navigator.reanchor

    def logged_reanchor(self, stored, beacon_frame=None):
        self._log = (list(self.edge_angles), tuple(stored))
        return reanchor(self, stored, beacon_frame)

    Navigator.reanchor = logged_reanchor
    vertex_call = Explorer._vertex_call

    def logged_call(self, beacon, now_s, arrived, out, back=False):
        nav = self.nav
        nav._log = None
        before, n0 = list(nav.edge_angles), len(self.calls)
        theta0 = nav.odometry.theta
        vertex_call(self, beacon, now_s, arrived, out, back)
        if len(self.calls) == n0:
            return
        odo = nav.odometry
        calls.append(dict(
            i=self.strategy.index, n=len(self.calls), t=now_s, beacon=beacon.id,
            dropped=self.strategy.stored_angles is None, measured=before,
            stored=None if nav._log is None else nav._log[1],
            correction=odo.theta - theta0, wheel_sq=odo.wheel_sq,
            slip_sigma=odo.slip_sigma, rb=odo.cal.wheel_radius_m / odo.track_m,
            scans=nav._scans, lane=getattr(nav, "_lane_log", None) if arrived else None))
        nav._lane_log = None

    Explorer._vertex_call = logged_call
    depart = Navigator.depart

    def logged_depart(self, angle):
        depart(self, angle)
        self._dep_wheel_sq = self.odometry.wheel_sq

    Navigator.depart = logged_depart
    lane_ended = Navigator._lane_ended

    def logged_lane_ended(self, lane, clear_m=0.0):
        if not self._returning and self._left is not None:
            self._lane_log = dict(dep=self._left[2], headings=list(lane.headings),
                                  theta=self.odometry.theta, wheel_sq=self.odometry.wheel_sq,
                                  dep_wheel_sq=getattr(self, "_dep_wheel_sq", 0.0))
        else:
            self._lane_log = None
        lane_ended(self, lane, clear_m)

    Navigator._lane_ended = logged_lane_ended
    after_step = ExplorationMetrics.after_step

    def sampled(self, loop):
        after_step(self, loop)
        poses = self._observed[1]
        controllers = loop.controllers
        for i in loop.stepped:
            if type(i) is int:
                c = controllers[i]
                state = c.telemetry()
                if state.get("on_edge") or c.calls and c.calls[-1].time_s == self._observed[0]:
                    e = math.remainder(state["heading_rad"] - poses[i, 2], 2 * math.pi)
                    s = samples.setdefault((i, len(c.calls)), [e, e, e, e])
                    s[0], s[1], s[3] = min(s[0], e), max(s[1], e), e

    ExplorationMetrics.after_step = sampled
    config = EmbodiedConfig(speed_m_s=args.speed, wheel_slip=args.wheel_slip,
                            line_noise_m=args.line_noise, ir_noise_m=args.ir_noise,
                            bearing_noise_deg=args.bearing_noise, physics=args.physics)
    r = run_exploration(load_arena(args.arena), args.robots, world="embodied",
                        seed=args.seed, config=config)
    print(f"{args.arena} seed {args.seed}: completed={r.completed} map={r.map_correct} "
          f"heading={r.heading_error_deg}")
    with open(args.out, "wb") as f:
        pickle.dump(dict(calls=calls, samples=samples, heading=r.heading_error_deg,
                         name=f"{args.arena} s{args.seed}"), f)


DIAG: list = []


def replay(rec: dict, rule) -> float:
    """The run's heading error (deg) under ``rule(robot, call, delta, beacon) ->
    correction``; ``robot`` and ``beacon`` are dicts the rule may keep state in. Appends
    ``(robot error, robot var, beacon frame error, beacon offset, beacon var)`` (rad,
    rad^2) before each fusion to ``DIAG``."""
    first = {key: v[2] for key, v in rec["samples"].items() if len(v) > 2}
    offset: dict[int, float] = {}  # robot -> its heading minus the recorded one (rad)
    offsets = {}  # (robot, calls done) -> offset then
    beacons: dict[str, dict] = {}
    robots: dict[int, dict] = {}
    for c in rec["calls"]:
        i = c["i"]
        d = offset.get(i, 0.0)
        robot = robots.setdefault(i, {"var": 0.0, "wheel_sq": 0.0})
        robot["var"] += (c["rb"] * c["slip_sigma"]) ** 2 * (c["wheel_sq"] - robot["wheel_sq"])
        robot["wheel_sq"] = c["wheel_sq"]
        lane = getattr(rule, "lane", None)
        if lane is not None:
            d += lane(robot, c)
        if c["dropped"]:
            robot.update(anchor=c["beacon"], resid=0.0, anchor_var=robot["var"])
            beacons[c["beacon"]] = {"shift": d, "offset": 0.0,
                                    "var": robot["var"] + SCAN_FRAME_VAR, "by": i,
                                    "true": first.get((i, c["n"]), math.nan) + d}
        elif c["stored"] is not None:
            b = beacons[c["beacon"]]
            measured = [m + d for m in c["measured"]]
            stored = [s + b["shift"] for s in c["stored"]]
            delta = frame_offset(measured, stored)
            e_pre = first.get((i, c["n"]), math.nan) - c["correction"] + d
            DIAG.append((e_pre, robot["var"], b["true"], b["offset"], b["var"], c["slip_sigma"]))
            d += rule(robot, c, delta, b) - c["correction"]
        offset[i] = d
        offsets[(i, c["n"])] = d
    worst = 0.0
    for (i, n), (lo, hi, *_) in rec["samples"].items():
        d = offsets.get((i, n), 0.0)
        worst = max(worst, abs(lo + d), abs(hi + d))
    return math.degrees(worst)


def adopt(robot, c, delta, b):
    return delta


def fuse(robot, c, delta, b, beacon_update=False, once=True, q_scale=1.0, r=SCAN_FRAME_VAR):
    if c["slip_sigma"] == 0.0:
        return delta
    if once and robot.get("scan") == c["scans"]:
        return 0.0
    robot["scan"] = c["scans"]
    pr = robot["var"] * q_scale
    s = pr + b["var"] + r
    y = delta - b["offset"]
    k = pr / s
    robot["var"] = pr * (1 - k) / q_scale
    if beacon_update:
        kb = b["var"] / s
        b["offset"] += kb * y
        b["var"] *= 1 - kb
    return k * y


def fuse_anchor(robot, c, delta, b, r=SCAN_FRAME_VAR):
    """B, except back at the beacon it fused with (or dropped) last, with no fusion
    since: its frame then agreed with the beacon's up to a known residual, and what it
    measures now beyond it is its own drift since (variance q), which it corrects by
    q / (q + 2 r) and leaves the beacon alone."""
    if c["slip_sigma"] == 0.0:
        return delta
    if robot.get("scan") == c["scans"]:
        return 0.0
    robot["scan"] = c["scans"]
    y = delta - b["offset"]
    if robot.get("anchor") == c["beacon"]:
        q = robot["var"] - robot["anchor_var"]
        k = q / (q + 2 * r)
        corr = k * (y - robot["resid"])
        robot["var"] = robot["anchor_var"] + q * (1 - k)
        robot["resid"] = y - corr
        robot["anchor_var"] = robot["var"]
        return corr
    pr = robot["var"]
    s = pr + b["var"] + r
    k, kb = pr / s, b["var"] / s
    robot["var"] = pr * (1 - k)
    b["offset"] += kb * y
    b["var"] *= 1 - kb
    robot["anchor"], robot["resid"], robot["anchor_var"] = c["beacon"], y * r / s, robot["var"]
    return k * y


def lane_correction(robot, c, window=None, wiggle_var=0.0):
    """The rotation (rad) its lane's direction calls for at an arrival: the lane ran
    along the edge it left by, at its departure angle in its own frame; the mean odometry
    heading over the lane's last ``window`` aligned samples (all: None) read ``z`` less
    than that. Weighted by the drift's variance over the lane ``q`` against the departure
    spoke's error and the follower's wiggle; the whole lane's mean sees only about half
    of the drift at its end (a random walk's mean), its last samples nearly all of it."""
    lane = c.get("lane")
    if not lane or not lane["headings"] or c["slip_sigma"] == 0.0:
        return 0.0
    hs = lane["headings"][-window:] if window else lane["headings"]
    mean = math.atan2(sum(map(math.sin, hs)), sum(map(math.cos, hs)))
    z = wrap(lane["dep"] - mean)
    q = (c["rb"] * c["slip_sigma"]) ** 2 * (lane["wheel_sq"] - lane["dep_wheel_sq"])
    r = SCAN_FRAME_VAR + wiggle_var / len(hs)
    if window is None:  # the mean of a random walk over the lane: cov q/2, var q/3
        gain, reduce = (q / 2) / (q / 3 + r), (q / 2) ** 2 / (q / 3 + r)
    else:
        gain, reduce = q / (q + r), q * q / (q + r)
    robot["var"] = max(robot["var"] - reduce, 0.0)
    return gain * z


def with_lane(rule, **kw):
    def combined(robot, c, delta, b):
        return rule(robot, c, delta, b)
    combined.lane = lambda robot, c: lane_correction(robot, c, **kw)
    return combined


RULES = {
    "adopt": adopt,
    "A": lambda r, c, d, b: fuse(r, c, d, b, once=False),
    "A1": fuse,
    "B": lambda r, c, d, b: fuse(r, c, d, b, beacon_update=True),
    "Bq.5": lambda r, c, d, b: fuse(r, c, d, b, beacon_update=True, q_scale=0.5),
    "Bq2": lambda r, c, d, b: fuse(r, c, d, b, beacon_update=True, q_scale=2.0),
    "BR.5": lambda r, c, d, b: fuse(r, c, d, b, beacon_update=True, r=SCAN_FRAME_VAR / 2),
    "BR2": lambda r, c, d, b: fuse(r, c, d, b, beacon_update=True, r=SCAN_FRAME_VAR * 2),
    "C": fuse_anchor,
    "BL": with_lane(RULES_B := (lambda r, c, d, b: fuse(r, c, d, b, beacon_update=True))),
    "BL20": with_lane(RULES_B, window=20),
    "BL10": with_lane(RULES_B, window=10),
}


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = p.add_subparsers(dest="cmd", required=True)
    rp = sub.add_parser("record")
    rp.add_argument("--arena", default="arena2")
    rp.add_argument("--robots", type=int, default=4)
    rp.add_argument("--speed", type=float, default=0.05)
    rp.add_argument("--wheel-slip", type=float, default=0.0)
    rp.add_argument("--line-noise", type=float, default=0.0)
    rp.add_argument("--ir-noise", type=float, default=0.0)
    rp.add_argument("--bearing-noise", type=float, default=0.0)
    rp.add_argument("--physics", default="dynamic")
    rp.add_argument("--seed", type=int, default=0)
    rp.add_argument("--out", required=True)
    pp = sub.add_parser("replay")
    pp.add_argument("files", nargs="+")
    pp.add_argument("--rules", default=",".join(RULES))
    args = p.parse_args()
    if args.cmd == "record":
        record(args)
        return
    names = args.rules.split(",")
    print("run".ljust(24) + "recorded".rjust(9) + "".join(n.rjust(9) for n in names))
    totals = {n: [] for n in names}
    for f in args.files:
        rec = pickle.load(open(f, "rb"))
        row = rec["name"].ljust(24) + f"{rec['heading']:9.2f}"
        for n in names:
            h = replay(rec, RULES[n])
            totals[n].append(h)
            row += f"{h:9.2f}"
        print(row)
    for n in names:
        h = totals[n]
        print(f"{n}: mean {sum(h) / len(h):.2f} worst {max(h):.2f} within 5: "
              f"{sum(x <= 5 for x in h)}/{len(h)}")


if __name__ == "__main__":
    main()

"""A summary picture of any run: ``mjswarm plot RESULT -o OUT.png``.

From a recording (``.rrd``, any run recorded with ``--record``): the arena when there is
one (the lines on the floor, the walls, the vertices with their names above everything
else), every robot's trajectory in its recording colour ending in a dot (a robot that
did not move, or never left the depot, is in the legend as such), the radio links at the end (blue,
dashed) when the robots had radios, where completion was declared (a star), contact
events (red crosses) and a table of headline figures read from the recording (robots,
simulated time, how the run ended, distance driven, contacts, completion). An arena
run's recording without its "run ended" event (an interrupted run) is titled partial.

From a ``--json`` result: an exploration run draws the arena's graph and each robot's
vertex-to-vertex path (the result holds paths, not trajectories; record the run for
those) with the declaring robot's vertex, and lists each robot's vertices in visit
order; a coverage run its S-coverage per episode against the paper's mean; a patrol run
its headline figures. The format follows the output file's extension (PNG, SVG, PDF:
matplotlib's).
"""

from __future__ import annotations

import json
import re
import textwrap
import warnings
from collections import defaultdict
from dataclasses import dataclass, field
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pyarrow as pa  # noqa: E402
import rerun as rr  # noqa: E402

from mjswarm.errors import MjswarmError, one_line  # noqa: E402
from mjswarm.core.contacts import CONTACT_PATTERN  # noqa: E402
from mjswarm.outputs.recording import robot_color  # noqa: E402

#: A stretch of trajectory that spans less than this (m) is a robot parked in a depot.
PARKED_M = 0.02
_DECLARED = re.compile(r"(R\d+) declared completion at (\S+)")
_ENDED = re.compile(r"^run ended: (.+)$")
_LAUNCHED = re.compile(r"^(R\d+) launched at ")
#: Colours of the floor's lines and of the walls.
LINE_COLOR, WALL_COLOR = "0.55", "saddlebrown"
#: Vertex names: above every line and mark, offset up and right from the centre (points).
LABEL_STYLE = dict(fontsize=7, color="0.2", textcoords="offset points", xytext=(5, 5),
                   zorder=8, bbox=dict(boxstyle="round,pad=0.15", fc="white", ec="none",
                                       alpha=0.8))
_ROBOT_POSE = re.compile(r"^/robots/(R\d+)/pose$")


@dataclass
class Trace:
    """What a recording holds that a summary picture shows (lengths in m, times in s)."""

    name: str = ""
    paths: dict[str, tuple[np.ndarray, np.ndarray]] = field(default_factory=dict)  # t, xy
    vertices: dict[str, tuple[float, float]] = field(default_factory=dict)
    strips: list[tuple[np.ndarray, np.ndarray]] = field(default_factory=list)  # segments
    walls: list[tuple[np.ndarray, np.ndarray]] = field(default_factory=list)  # segments
    links: list[np.ndarray] = field(default_factory=list)  # radio links at the end
    events: list[tuple[float, str]] = field(default_factory=list)


def read_recording(path: str | Path) -> Trace:
    """The :class:`Trace` of an ``.rrd`` written by :mod:`mjswarm.outputs.recording`."""
    trace = Trace(name=Path(path).stem)
    poses: dict[str, list] = defaultdict(list)
    last_links: tuple[int, list] = (-1, [])
    try:
        with warnings.catch_warnings():  # the reader's notes on the file's layout
            warnings.simplefilter("ignore", rr.error_utils.RerunWarning)
            chunks = list(rr.chunk.RrdReader(path).stream())
    except Exception as exc:  # noqa: BLE001 - any reader failure means "not a recording"
        raise MjswarmError(f"cannot read recording {path}: {one_line(exc)}") from None
    for chunk in chunks:
        batch = chunk.to_record_batch()
        columns = {name: batch.column(name) for name in batch.schema.names}
        entity = chunk.entity_path
        times = (columns["sim_time"].cast(pa.int64()).to_numpy() / 1e9
                 if "sim_time" in columns else None)
        robot = _ROBOT_POSE.match(entity)
        if entity == "/__properties" and "RecordingInfo:name" in columns:
            trace.name = columns["RecordingInfo:name"].to_pylist()[0][0]
        elif robot and "Transform3D:translation" in columns and times is not None:
            xyz = columns["Transform3D:translation"].to_pylist()
            poses[robot.group(1)] += [(t, p[0][0], p[0][1]) for t, p in zip(times, xyz) if p]
        elif entity == "/arena/vertices" and "Points3D:positions" in columns:
            points = columns["Points3D:positions"].to_pylist()[0]
            labels = columns["Points3D:labels"].to_pylist()[0]
            trace.vertices = {v: (p[0], p[1]) for v, p in zip(labels, points)}
        elif entity == "/arena/strips" and "Boxes3D:centers" in columns:
            trace.strips = _segments(columns)
        elif entity == "/arena/walls" and "Boxes3D:centers" in columns:
            trace.walls = _segments(columns)
        elif entity == "/radio/links" and times is not None:
            for t, strips in zip(times, columns["LineStrips3D:strips"].to_pylist()):
                if t >= last_links[0]:
                    last_links = (t, strips or [])
        elif entity.startswith("/events") and "TextLog:text" in columns and times is not None:
            for t, texts in zip(times, columns["TextLog:text"].to_pylist()):
                trace.events += [(float(t), text) for text in texts or []]
    if not poses:
        raise MjswarmError(f"{path} holds no robot poses: is it an mjswarm recording?")
    for robot, rows in poses.items():
        rows.sort()
        data = np.array(rows)
        trace.paths[robot] = (data[:, 0], data[:, 1:3])
    trace.links = [np.array(s)[:, :2] for s in last_links[1]]
    trace.events.sort()
    return trace


def _segments(columns) -> list[tuple[np.ndarray, np.ndarray]]:
    """Floor strips or walls as segments: each box's long axis, turned by its
    quaternion."""
    centers = np.array(columns["Boxes3D:centers"].to_pylist()[0])
    halves = np.array(columns["Boxes3D:half_sizes"].to_pylist()[0])
    quats = np.array(columns["Boxes3D:quaternions"].to_pylist()[0])  # x, y, z, w
    yaw = 2.0 * np.arctan2(quats[:, 2], quats[:, 3])
    axis = np.stack([np.cos(yaw), np.sin(yaw)], axis=1) * halves[:, :1]
    return [(c[:2] - a, c[:2] + a) for c, a in zip(centers, axis)]


def _robot_index(name: str) -> int:
    return int(name[1:]) - 1


def plot_recording(path: str | Path, out: str | Path, fmt: str = "png") -> None:
    """Summary picture of a recorded run (module docstring)."""
    trace = read_recording(path)
    fig, (ax, table_ax) = plt.subplots(1, 2, figsize=(11, 6),
                                       gridspec_kw={"width_ratios": [3, 1.3]})
    _draw_arena(ax, trace)
    for link in trace.links:
        ax.plot(link[:, 0], link[:, 1], color="tab:blue", linestyle="--", linewidth=0.8,
                zorder=2)
    if trace.links:
        ax.plot([], [], color="tab:blue", linestyle="--", linewidth=0.8,
                label="radio link at the end")
    driven = {}
    launched = {m.group(1) for _, text in trace.events if (m := _LAUNCHED.match(text))}
    for robot, (_, xy) in sorted(trace.paths.items(), key=lambda kv: _robot_index(kv[0])):
        moved = np.linalg.norm(np.diff(xy, axis=0), axis=1)
        keep = np.concatenate([[True], moved < 1.0])  # a launch from the depot is a jump
        driven[robot] = float(moved[moved < 1.0].sum())
        color = np.array(robot_color(_robot_index(robot))) / 255.0
        segments = [seg for seg in np.split(xy, np.flatnonzero(~keep))
                    if np.ptp(seg, axis=0).max() > PARKED_M]  # not the depot
        for seg in segments:
            ax.plot(seg[:, 0], seg[:, 1], color=color, linewidth=1.3, zorder=3)
        if segments:
            ax.plot(*segments[-1][-1], marker="o", color=color, markersize=6, zorder=4)
        still = ("never left the depot" if trace.vertices and robot not in launched
                 else "did not move")
        ax.plot([], [], color=color, linewidth=1.3,
                label=robot if segments else f"{robot} ({still})")
    ax.plot([], [], marker="o", color="0.3", linestyle="none", markersize=6,
            label="where a robot was last")
    contacts = [m for _, text in trace.events if (m := CONTACT_PATTERN.search(text))]
    if contacts:
        ax.scatter([float(m.group(3)) for m in contacts], [float(m.group(4)) for m in contacts],
                   marker="x", color="red", s=60, zorder=5, label="contact")
    declared = [(t, m) for t, text in trace.events if (m := _DECLARED.search(text))]
    if declared and declared[0][1].group(2) in trace.vertices:
        ax.scatter(*trace.vertices[declared[0][1].group(2)], marker="*", s=260,
                   color="gold", edgecolor="black", zorder=6, label="completion declared")
    ended = [m.group(1) for _, text in trace.events if (m := _ENDED.search(text))]
    partial = bool(trace.vertices) and ended[-1:] in ([], ["interrupted"])
    _frame(ax, f"{trace.name}: trajectories (ground truth)"
               + (", PARTIAL: the run was interrupted" if partial else ""))
    end = max(t[-1] for t, _ in trace.paths.values())
    rows = [("robots", str(len(trace.paths))), ("simulated time", f"{end:.1f} s")]
    if trace.vertices:
        rows.append(("run ended", ended[-1] if ended else "not recorded (partial)"))
    rows.append(("contact events", str(len(contacts))))
    if declared:
        t, m = declared[0]
        rows.append(("completion", f"{m.group(1)} at {m.group(2)}, {t:.1f} s"))
    rows += [(f"{r} drove", f"{d:.2f} m") for r, d in sorted(
        driven.items(), key=lambda kv: _robot_index(kv[0]))]
    _table(table_ax, rows, trace.name)
    _save(fig, out, fmt)


def _draw_arena(ax, trace: Trace) -> None:
    """The floor's lines, the walls and the named vertices (each in the legend)."""
    for segments, color, width, label in ((trace.strips, LINE_COLOR, 1.5, "line on the floor"),
                                          (trace.walls, WALL_COLOR, 2.5, "wall")):
        for k, (a, b) in enumerate(segments):
            ax.plot([a[0], b[0]], [a[1], b[1]], color=color, linewidth=width, zorder=1,
                    solid_capstyle="butt", label=None if k else label)
    _draw_vertices(ax, trace.vertices)


def _draw_vertices(ax, vertices: dict[str, tuple[float, float]]) -> None:
    if not vertices:
        return
    xy = np.array(list(vertices.values()))
    ax.scatter(xy[:, 0], xy[:, 1], s=14, color="white", edgecolor="0.2", linewidth=0.8,
               zorder=7, label="vertex")
    for v, (x, y) in vertices.items():
        ax.annotate(v, (x, y), **LABEL_STYLE)


def _frame(ax, title: str) -> None:
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.grid(True, linewidth=0.3)
    ax.legend(fontsize=7, loc="best", ncol=2, framealpha=0.9)
    ax.set_title(title)


def _table(ax, rows: list[tuple[str, str]], title: str) -> None:
    ax.axis("off")
    table = ax.table(cellText=[[a, b] for a, b in rows], loc="upper center", cellLoc="left")
    table.auto_set_font_size(False)
    table.set_fontsize(8)
    table.scale(1.0, 1.3)
    ax.set_title(title, fontsize=9)


def _save(fig, out: str | Path, fmt: str) -> None:
    fig.tight_layout()
    try:
        fig.savefig(out, format=fmt)
    except (ValueError, OSError) as exc:
        raise MjswarmError(f"cannot write plot {out}: {one_line(exc)}") from None
    finally:
        plt.close(fig)


def plot_result(path: str | Path, out: str | Path, fmt: str = "png") -> None:
    """Summary picture of a ``--json`` result (module docstring)."""
    try:
        data = json.loads(Path(path).read_text())
    except (OSError, ValueError) as exc:
        raise MjswarmError(f"cannot read result {path}: {one_line(exc)}") from None
    if isinstance(data, dict) and "paths" in data and "arena" in data:
        _plot_exploration(data, out, fmt)
    elif isinstance(data, dict) and "episodes" in data and "cr" in data:
        _plot_coverage(data, out, fmt)
    elif isinstance(data, dict) and "disconnections_per_trial" in data:
        _plot_patrol(data, out, fmt)
    else:
        raise MjswarmError(f"{path} is not an exploration, coverage or patrol result")


def _plot_exploration(data: dict, out, fmt: str) -> None:
    from mjswarm.arena import load_arena

    spec = load_arena(data["arena"])
    fig, (ax, table_ax) = plt.subplots(1, 2, figsize=(11, 6),
                                       gridspec_kw={"width_ratios": [3, 1.3]})
    for n, (u, v) in enumerate(spec.edges):
        (x0, y0), (x1, y1) = spec.vertices[u], spec.vertices[v]
        ax.plot([x0, x1], [y0, y1], color="0.75", linewidth=2, zorder=1,
                label=None if n else "edge")
    _draw_vertices(ax, spec.vertices)
    k = len(data["paths"])
    for i, path in enumerate(data["paths"]):
        shift = 0.03 * (i - (k - 1) / 2)  # side by side where robots share an edge
        xy = np.array([spec.vertices[v] for v in path]) + shift
        ax.plot(xy[:, 0], xy[:, 1], color=np.array(robot_color(i)) / 255.0, linewidth=1.5,
                marker=".", label=f"R{i + 1}", zorder=3)
    if data.get("declared_at") in spec.vertices:
        ax.scatter(*spec.vertices[data["declared_at"]], marker="*", s=260, color="gold",
                   edgecolor="black", zorder=6, label="completion declared")
    name = f"{data['arena']}, {k} robots, {data.get('world', '')} world"
    _frame(ax, f"{name}: vertex paths")
    rows = [("completed", "yes" if data.get("completed") else "no"),
            ("makespan (steps)", str(data.get("makespan"))),
            ("edge traversals", str(data.get("total_traversals"))),
            ("map correct", "yes" if data.get("map_correct") else "no")]
    for key, label, unit in (("collisions", "contact events", ""),
                             ("sim_time_s", "simulated time", " s")):
        if data.get(key) is not None:
            value = data[key]
            rows.append((label, f"{value:.1f}{unit}" if isinstance(value, float) else
                         f"{value}{unit}"))
    _table(table_ax, rows, name)
    order = "\n".join(textwrap.fill(f"R{i + 1}: " + " ".join(path), 44,
                                     subsequent_indent="     ")
                       for i, path in enumerate(data["paths"]))
    table_ax.text(0.0, 0.55, "vertices in visit order\n" + order, fontsize=7, va="top",
                  family="monospace", transform=table_ax.transAxes)
    _save(fig, out, fmt)


def _plot_coverage(data: dict, out, fmt: str) -> None:
    fig, ax = plt.subplots(figsize=(8, 4.5))
    episodes = [e for e in data["episodes"] if e["coverage"] is not None]
    ax.plot([e["index"] + 1 for e in episodes], [100 * e["coverage"] for e in episodes],
            marker=".", label=f"this run: mean {100 * data['mean_coverage']:.1f} %")
    if data.get("paper_mean_coverage") is not None:
        ax.axhline(100 * data["paper_mean_coverage"], color="black", linestyle="--",
                   label=f"paper: {100 * data['paper_mean_coverage']:.0f} %")
    ax.set_xlabel("episode")
    ax.set_ylabel("S-coverage (%)")
    ax.set_title(f"biconnected coverage (Ahmadi & Stone), cr {data['cr']:g}, "
                 f"{data['placement']} placement, {data['world']} world, seed {data['seed']}")
    ax.grid(True, linewidth=0.3)
    ax.legend()
    _save(fig, out, fmt)


def _plot_patrol(data: dict, out, fmt: str) -> None:
    fig, ax = plt.subplots(figsize=(7, 4))
    rows = [("robots", str(data["robots"])), ("trials x steps",
                                              f"{data['trials']} x {data['steps']}"),
            ("disconnections per trial", f"{data['disconnections_per_trial']:.2f}"),
            ("targets per trial", f"{data['targets_per_trial']:.1f}"),
            ("messages per robot per step", f"{data['messages_per_robot_step']:.2f}"),
            ("algebraic connectivity", f"{data['algebraic_connectivity']:.3f}")]
    if data.get("collisions_per_trial") is not None:
        rows.append(("contacts per trial", f"{data['collisions_per_trial']:.1f}"))
    _table(ax, rows, f"patrol (Kobayashi et al.), {data['world']} world")
    _save(fig, out, fmt)


#: Picture formats by file extension.
FORMATS = ("png", "svg", "pdf")


def picture_format(out: str | Path) -> str:
    """The format a picture's file name asks for; :class:`MjswarmError` if none we write."""
    fmt = Path(out).suffix.lower().lstrip(".")
    if fmt not in FORMATS:
        raise MjswarmError(f"the picture must be .png, .svg or .pdf, got {out}")
    return fmt


def plot(result: str | Path, out: str | Path, fmt: str | None = None) -> None:
    """``mjswarm plot``: a recording or a JSON result to a picture in ``fmt`` (default:
    from ``out``'s extension)."""
    fmt = fmt or picture_format(out)
    if not Path(result).is_file():
        raise MjswarmError(f"no such file: {result}")
    if Path(result).suffix.lower() == ".rrd":
        plot_recording(result, out, fmt)
    else:
        plot_result(result, out, fmt)


__all__ = ["Trace", "plot", "plot_recording", "plot_result", "read_recording"]

"""Rerun recordings of runs, written headless to an ``.rrd`` file.

A :class:`Recorder` writes one rerun (0.41) recording: the arena as static data, every
robot's pose, trail and sensor readings per control tick, and the rarer things (events,
explored graphs, beacon contents, the radio graph) when they happen, plus a blueprint
so the file opens ready to review (``mjswarm view FILE.rrd`` or ``rerun FILE.rrd``).
No display is needed to write one. Ground truth (poses) is fine here: recordings are
for reviewers, never read by controllers.

Entity tree (all lengths in metres, angles in radians, speeds in m/s; the world frame
is right-handed, z up, the floor at z = 0)::

    arena/strips              Boxes3D, static: lane strips and vertex spokes
    arena/walls               Boxes3D, static: corridor walls
    arena/vertices            Points3D, static: vertex centres labelled with arena ids
    robots/R<k>/pose          Transform3D per tick (x, y, yaw) + static Cylinders3D body
    robots/R<k>/pose/heading  Arrows3D, static, in the robot frame: the heading
    robots/R<k>/trail         LineStrips3D per tick: the segment driven since the last tick
    robots/R<k>/speed         Scalars per tick: commanded linear speed
    robots/R<k>/sensors/line  Scalars per tick, 3 series: line rangefinders (left, centre, right)
    robots/R<k>/sensors/ir    Scalars per tick, 3 series: IR distances, NaN = nothing seen
    robots/R<k>/sensors/encoders  Scalars per tick, 2 series: wheel angles (rad)
    robots/R<k>/battery       Scalars per tick: battery terminal voltage (V)
    robots/R<k>/bearings/R<j> Scalars (drawn as points) at ticks where R<k> sees R<j>
    robots/R<k>/state         Scalars per tick: the controller's telemetry, one series a name
    states/R<k>/decision      StateChange: its decision at each vertex call (go, idle, done)
    states/R<k>/mode          StateChange: its mode (a tethered robot's), when it changes
    map/R<k>                  GraphNodes + GraphEdges: robot R<k>'s explored graph, in graph
                              units (:attr:`Recorder.graph_scale` units per metre)
    matrices/R<k>             TextDocument (markdown): the incidence matrix R<k> carries,
                              after each of its vertex calls
    beacons/<vertex>          TextDocument: the beacon's contents (beacon-side vertex id)
    radio/graph               GraphNodes + GraphEdges: who hears whom, laid out by the viewer
    radio/links               LineStrips3D: the same edges drawn between the robots
    radio/tethers             LineStrips3D: each robot's link to its tether parent
    radio/truth               TextDocument: ground truth and the robots' beliefs
    regions                   LineStrips3D: the regions robots guard, as circles on the floor
    events                    TextLog: run-wide events (launches of faults, completion, the end)
    events/R<k>               TextLog: robot R<k>'s events (vertex visits, speed changes, stops)

Robots are numbered from 1, R1..RK, as everywhere a user sees them (the CLI, JSON,
``--launch-order``); the methods take 0-based indices (robot ``i`` is ``R{i+1}``).
The blueprint shows the radio views only for runs with radios (``radio=True``).

Everything not static is on two timelines: ``step`` (control tick, a sequence) and
``sim_time`` (simulated seconds, a duration). The SDK's own ``log_tick``/``log_time``
timelines are switched off so a recording carries only simulation time.

Per-tick data is buffered in numpy arrays and sent with ``send_columns`` every
``chunk_ticks`` ticks and at :meth:`Recorder.close`; per-call logging would cost far more
per tick. Choices:

* The trail is one short segment per tick (previous position -> current position); the
  blueprint shows the last ``trail_window_s`` of segments (a per-entity visible time
  range), which is rerun's documented way to draw trails and costs 2 points per tick
  instead of a whole strip.
* Bearings are sparse (a robot sees few others), so each observed pair gets its own
  series, drawn as points, sent only at the ticks of the observations.
* The maps (``map/*``) use the vertices' positions, with y negated and
  scaled by :attr:`Recorder.graph_scale`: rerun's graph view draws y downwards, and
  places nodes in its own units, where a node's label is some 30-60 units wide, so the
  scale puts the closest two vertices of the arena :data:`GRAPH_SPACING` units apart
  and every vertex's label stands apart from the others. The radio graph
  (``radio/graph``) is topology, and robots often stand together (on the root, in the
  depot), so the viewer lays it out by forces; ``radio/links`` draws it over the arena.
* The arena view looks straight down on the arena (x to the right, y up), from a
  height at which the arena fills the view.
* An explored graph identical to the one last logged for that robot is not logged again.
"""

from __future__ import annotations

import colorsys
import os
import shutil
import subprocess
import sys
import uuid
from collections.abc import Mapping, Sequence
from importlib.util import find_spec
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import rerun as rr
import rerun.blueprint as rrb

from mjswarm.arena.builder import arena_primitives
from mjswarm.arena.spec import ArenaSpec
from mjswarm.errors import MjswarmError, one_line
from mjswarm.worlds.loop import Loop, LoopFunctions
from mjswarm.core.contacts import contact_event, robot_name
from mjswarm.core.robot import ENCODERS, IR_SENSORS, LINE_SENSORS

if TYPE_CHECKING:
    from typing_extensions import Self

APPLICATION_ID = "mjswarm"
#: Robot body height for drawing (m): the Spark V is 7 cm tall (DESIGN.md).
ROBOT_HEIGHT_M = 0.07
#: Ticks buffered before a columnar send.
CHUNK_TICKS = 500
#: How much trail the blueprint shows behind each robot (simulated s).
TRAIL_WINDOW_S = 30.0
#: Above this many robots the blueprint shows all explored graphs in one graph view
#: instead of one tab per robot.
MAP_TAB_LIMIT = 8
#: Graph-view units between the two closest vertices of the arena (a label is at most
#: some 60 units wide).
GRAPH_SPACING = 90.0
#: Vertical field of view of rerun's 3-D view (degrees), for framing the arena.
_FOV_Y_DEG = 55.0
_TRAIL_Z_M = 0.004
_VERTEX_Z_M = 0.006
_STRIP_COLOR = (30, 30, 30, 255)
_WALL_COLOR = (150, 150, 165, 140)
_VERTEX_COLOR = (220, 40, 40, 255)
_ROOT_COLOR = (240, 190, 20, 255)
_AGREE_COLOR = (40, 170, 60, 255)
_DISAGREE_COLOR = (220, 40, 40, 255)
_NO_BELIEF_COLOR = (140, 140, 140, 255)


def robot_color(i: int) -> tuple[int, int, int, int]:
    """A distinct RGBA colour for robot ``i`` (golden-ratio hue steps)."""
    r, g, b = colorsys.hsv_to_rgb((i * 0.618033988749895) % 1.0, 0.75, 0.95)
    return int(r * 255), int(g * 255), int(b * 255), 255


def rerun_command() -> list[str]:
    """The argv prefix that runs the ``rerun`` CLI shipped with rerun-sdk.

    The binary lives in the ``rerun_cli`` package next to the SDK; ``rerun`` on PATH is
    the fallback. Raises :class:`MjswarmError` if neither exists.
    """
    spec = find_spec("rerun_cli")
    if spec is not None and spec.origin is not None:
        binary = Path(spec.origin).parent / ("rerun.exe" if sys.platform == "win32" else "rerun")
        if binary.is_file():
            return [str(binary)]
    on_path = shutil.which("rerun")
    if on_path is None:
        raise MjswarmError("the rerun CLI was not found (is rerun-sdk installed?)")
    return [on_path]


def has_display() -> bool:
    """Whether a viewer window can open: on Linux and other X11/Wayland systems, DISPLAY
    or WAYLAND_DISPLAY must be set; macOS and Windows always have a display."""
    if sys.platform in ("darwin", "win32"):
        return True
    return bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))


def check_recording(path: str | Path) -> None:
    """Refuse, in one line, a path that is no rerun recording (rerun's files start
    with ``RRF``)."""
    path = Path(path)
    if not path.is_file():
        raise MjswarmError(f"no recording at {path}")
    with path.open("rb") as f:
        if f.read(3) != b"RRF":
            raise MjswarmError(f"{path} is not a rerun .rrd recording")


def open_viewer(path: str | Path) -> int:
    """Open the recording at ``path`` in the rerun viewer; returns the viewer's exit status.

    Blocks until the viewer window is closed. Raises :class:`MjswarmError` (one line,
    at once) if the file is missing or not an ``.rrd`` recording (:func:`check_recording`),
    or if there is no display.
    """
    path = Path(path)
    check_recording(path)
    if not has_display():
        raise MjswarmError(
            f"no display (DISPLAY and WAYLAND_DISPLAY are unset), cannot open the viewer; "
            f"serve it to a browser with `mjswarm view {path} --web`"
        )
    return subprocess.call([*rerun_command(), str(path)])


def _yaw_quaternions(yaw: np.ndarray) -> np.ndarray:
    """Quaternions (x, y, z, w: rerun's order) of rotations by ``yaw`` (rad) about +z."""
    half = np.asarray(yaw, dtype=float) / 2.0
    quat = np.zeros(half.shape + (4,))
    quat[..., 2] = np.sin(half)
    quat[..., 3] = np.cos(half)
    return quat


def _segment_boxes(segments, width_m: float, height_m: float, z0_m: float):
    """Centres, half sizes and yaw quaternions of boxes ``width_m`` x ``height_m`` along
    the given segments (objects with ``.start`` and ``.end`` (x, y) in m), base at z0."""
    start = np.array([s.start for s in segments], dtype=float).reshape(-1, 2)
    end = np.array([s.end for s in segments], dtype=float).reshape(-1, 2)
    delta = end - start
    centres = np.column_stack([(start + end) / 2.0, np.full(len(start), z0_m + height_m / 2.0)])
    half = np.column_stack([
        np.hypot(delta[:, 0], delta[:, 1]) / 2.0,
        np.full(len(start), width_m / 2.0),
        np.full(len(start), height_m / 2.0),
    ])
    return centres, half, _yaw_quaternions(np.arctan2(delta[:, 1], delta[:, 0]))


class Recorder:
    """Writes a run to a rerun ``.rrd`` file; see the module docstring for the tree.

    Args:
        path: the ``.rrd`` file to write (its directory must exist).
        arena: the arena the run happens in (drawn as static data); None for an open floor.
        n_robots: team size; robots are R1..RK (indices 0..K-1 in the methods).
        robot_radius_m: body radius for drawing (m).
        chunk_ticks: ticks buffered between columnar sends.
        trail_window_s: simulated seconds of trail the blueprint shows.
        radio: whether the run has radios (the blueprint then shows the radio views).
        sensors: whether ticks carry the Spark V's sensor readings (line, IR, encoders,
            battery, bearings); without them a tick is poses (and speeds) only.
        bounds_m: ``(x_min, y_min, x_max, y_max)`` of the area to frame (default: the
            arena's vertices; needed without an arena).
        name: the recording's name (default: the arena's name and the team size).
        video: whether the run also makes a video that :meth:`log_video` will add (the
            blueprint then shows a camera view beside the 3-D view).

    Raises :class:`MjswarmError` (one line) if the file cannot be created or a
    parameter is impossible. Use as a context manager or call :meth:`close`.
    """

    def __init__(
        self,
        path: str | Path,
        arena: ArenaSpec,
        n_robots: int,
        robot_radius_m: float = 0.075,
        *,
        chunk_ticks: int = CHUNK_TICKS,
        trail_window_s: float = TRAIL_WINDOW_S,
        radio: bool = False,
        sensors: bool = True,
        bounds_m: tuple[float, float, float, float] | None = None,
        name: str | None = None,
        video: bool = False,
    ) -> None:
        if int(n_robots) != n_robots or n_robots < 1:
            raise MjswarmError(f"a recording needs at least 1 robot, got {n_robots}")
        if not robot_radius_m > 0.0:
            raise MjswarmError(f"robot radius must be > 0 m, got {robot_radius_m}")
        if int(chunk_ticks) != chunk_ticks or chunk_ticks < 1:
            raise MjswarmError(f"chunk_ticks must be a whole number >= 1, got {chunk_ticks}")
        if not trail_window_s > 0.0:
            raise MjswarmError(f"trail window must be > 0 s, got {trail_window_s}")
        if arena is None and bounds_m is None:
            raise MjswarmError("a recording without an arena needs the bounds of its area")
        if bounds_m is None:
            xy = np.array(list(arena.vertices.values()))
            bounds_m = (*xy.min(axis=0), *xy.max(axis=0))
        #: graph-view units per metre (module docstring)
        self.graph_scale = graph_scale(None if arena is None else arena.vertices.values(),
                                       bounds_m)
        self.path = Path(path)
        self.sensors = sensors
        self.n_robots = n = int(n_robots)
        self._chunk = int(chunk_ticks)
        if self.path.is_dir():
            raise MjswarmError(f"cannot write recording {self.path}: it is a directory")
        if not self.path.parent.is_dir():
            raise MjswarmError(
                f"cannot write recording {self.path}: directory {self.path.parent} does not exist"
            )
        self._stream = rr.RecordingStream(APPLICATION_ID, recording_id=uuid.uuid4())
        try:
            self._stream.save(self.path)
        except RuntimeError as exc:
            raise MjswarmError(f"cannot write recording {self.path}: {one_line(exc)}") from None
        self._stream.set_log_tick_enabled(False)
        self._stream.set_log_time_enabled(False)
        self._stream.send_recording_name(name or f"{arena.name}, {n} robots")
        self._stream.send_blueprint(_blueprint(bounds_m, n, trail_window_s, radio, sensors,
                                               video, self.graph_scale,
                                               maps=arena is not None))
        self._closed = False
        #: Ticks logged so far (0: the file holds the static scene only, no pose).
        self.ticks = 0
        self._buffers(self._chunk, n)
        self._log_static(arena, float(robot_radius_m))

    def _buffers(self, b: int, n: int) -> None:
        """The buffers of ``b`` ticks of ``n`` robots that :meth:`log_tick` fills."""
        self._rows = 0
        self._steps = np.zeros(b, dtype=np.int64)
        self._times = np.zeros(b)
        self._poses = np.zeros((b, n, 3))
        self._line = np.zeros((b, n, 3))
        self._ir = np.zeros((b, n, 3))
        self._speed = np.zeros((b, n))
        self._encoders = np.zeros((b, n, 2))
        self._battery = np.zeros((b, n))
        self._bearing_rows: list[int] = []
        self._bearing_pairs: list[int] = []  # observer * n + other
        self._bearing_values: list[float] = []
        self._bearing_series: set[int] = set()
        self._trail_from: np.ndarray | None = None  # (n, 2): last position already sent
        self._latest_xy: np.ndarray | None = None  # (n, 2): last position logged
        self._last_map: dict[int, tuple] = {}
        self._last_state: dict[tuple[int, str], str] = {}
        self._regions: dict[int, tuple[float, float, float]] = {}
        self._state: dict[tuple[int, str], tuple[list[int], list[float]]] = {}

    # --- static data -------------------------------------------------------------------

    def _log_static(self, arena: ArenaSpec | None, radius_m: float) -> None:
        log = self._stream.log
        log("/", rr.ViewCoordinates.RIGHT_HAND_Z_UP, static=True)
        if arena is not None:
            self._log_arena(arena)
        for i in range(self.n_robots):
            color = robot_color(i)
            log(f"robots/{robot_name(i)}/pose", rr.Cylinders3D(
                lengths=ROBOT_HEIGHT_M, radii=radius_m, centers=(0.0, 0.0, ROBOT_HEIGHT_M / 2),
                colors=color, labels=robot_name(i), fill_mode="solid",
            ), static=True)
            log(f"robots/{robot_name(i)}/pose/heading", rr.Arrows3D(
                origins=(0.0, 0.0, ROBOT_HEIGHT_M + 0.005), vectors=(1.5 * radius_m, 0.0, 0.0),
                colors=(255, 255, 255, 255), radii=0.006,
            ), static=True)
            name = robot_name(i)
            log(f"robots/{name}/trail", rr.LineStrips3D.from_fields(colors=color, radii=0.004),
                static=True)  # style only: static strips would hide the temporal ones
            log(f"robots/{name}/speed", rr.SeriesLines(names=name, colors=color), static=True)
            if not self.sensors:
                continue
            log(f"robots/{name}/battery", rr.SeriesLines(names=name, colors=color), static=True)
            for kind, names in (("line", LINE_SENSORS), ("ir", IR_SENSORS),
                                ("encoders", ENCODERS)):
                log(f"robots/{name}/sensors/{kind}",
                    rr.SeriesLines(names=[f"{name} {s}" for s in names]), static=True)

    def _log_arena(self, arena: ArenaSpec) -> None:
        log = self._stream.log
        strips, walls = arena_primitives(arena)
        if strips:
            c, h, q = _segment_boxes(strips, strips[0].width_m, strips[0].thickness_m, 0.0)
            log("arena/strips", rr.Boxes3D(centers=c, half_sizes=h, quaternions=q,
                                           colors=_STRIP_COLOR, fill_mode="solid"), static=True)
        if walls:
            c, h, q = _segment_boxes(walls, walls[0].thickness_m, walls[0].height_m, 0.0)
            log("arena/walls", rr.Boxes3D(centers=c, half_sizes=h, quaternions=q,
                                          colors=_WALL_COLOR, fill_mode="solid"), static=True)
        ids = list(arena.vertices)
        log("arena/vertices", rr.Points3D(
            [(x, y, _VERTEX_Z_M) for x, y in arena.vertices.values()],
            labels=ids, radii=0.015, show_labels=True,
            colors=[_ROOT_COLOR if v == arena.root else _VERTEX_COLOR for v in ids],
        ), static=True)

    # --- per tick ----------------------------------------------------------------------

    def log_tick(
        self,
        step: int,
        sim_time_s: float,
        poses: np.ndarray,
        line: np.ndarray | None = None,
        ir: np.ndarray | None = None,
        speed: np.ndarray | None = None,
        bearings: Sequence[Sequence[tuple[int, float]]] | None = None,
        encoders: np.ndarray | None = None,
        battery: np.ndarray | None = None,
        state: Mapping[int, Mapping[str, float]] | None = None,
    ) -> None:
        """Buffer one control tick; sends a chunk every ``chunk_ticks`` ticks.

        Args:
            step: control tick number.
            sim_time_s: simulated time (s).
            poses: (N, 3) x (m), y (m), yaw (rad) per robot.
            line: (N, 3) line rangefinder readings (m), order of ``robot.LINE_SENSORS``.
            ir: (N, 3) IR distances (m), NaN = nothing, order of ``robot.IR_SENSORS``.
            speed: (N,) commanded linear speed (m/s); None: not logged (zeros).
            bearings: per robot, the (other robot, bearing in rad) pairs it sees.
            encoders: (N, 2) wheel angles (rad), left and right.
            battery: (N,) battery terminal voltage (V).
            state: per robot index, named numbers describing its controller's state
                (one series per name, ``robots/R<k>/state/<name>``).

        The sensor readings (line, IR, bearings, encoders, battery) are required when the
        recorder was made with ``sensors=True`` and refused otherwise.
        """
        self._check_open()
        n = self.n_robots
        speed = np.zeros(n) if speed is None else speed
        self._check_tick(poses, speed, line, ir, bearings, encoders, battery)
        k = self._rows
        self.ticks += 1
        self._steps[k] = step
        self._times[k] = sim_time_s
        self._poses[k] = poses
        self._speed[k] = speed
        if self.sensors:
            self._line[k] = line
            self._ir[k] = ir
            self._encoders[k] = encoders
            self._battery[k] = battery
        for i, values in (state or {}).items():
            for name, value in values.items():
                rows, series = self._state.setdefault((i, name), ([], []))
                rows.append(k)
                series.append(float(value))
        for i, seen in enumerate(bearings or ()):
            for j, bearing in seen:
                self._bearing_rows.append(k)
                self._bearing_pairs.append(i * n + j)
                self._bearing_values.append(bearing)
        self._rows = k + 1
        if self._rows == self._chunk:
            self._send_ticks()

    def _check_tick(self, poses, speed, line, ir, bearings, encoders, battery) -> None:
        """:meth:`log_tick`'s arguments have the shapes of this recording's robots, and
        the sensor readings are there exactly when the recording has sensors."""
        n = self.n_robots
        readings = (line, ir, bearings, encoders, battery)
        if self.sensors and any(r is None for r in readings):
            raise ValueError("log_tick: this recording needs every sensor reading")
        if not self.sensors and any(r is not None for r in readings):
            raise ValueError("log_tick: this recording was made without sensors")
        checks = [("poses", poses, (n, 3)), ("speed", speed, (n,))]
        if self.sensors:
            checks += [("line", line, (n, 3)), ("ir", ir, (n, 3)),
                       ("encoders", encoders, (n, 2)), ("battery", battery, (n,))]
            if len(bearings) != n:
                raise ValueError(f"log_tick: bearings has {len(bearings)} entries, expected {n}")
        for name, value, shape in checks:
            if np.shape(value) != shape:
                raise ValueError(f"log_tick: {name} has shape {np.shape(value)}, expected {shape}")

    def _send_ticks(self) -> None:
        """Send the buffered ticks as columns (one ``send_columns`` per entity)."""
        k, n = self._rows, self.n_robots
        if k == 0:
            return
        send = self._stream.send_columns
        # rerun may keep the arrays it is given and encode them later (zero copy), so it
        # gets copies, never views of the buffers that the next ticks overwrite.
        steps, times = self._steps[:k].copy(), self._times[:k].copy()
        speed, line, ir = self._speed[:k].copy(), self._line[:k].copy(), self._ir[:k].copy()
        encoders, battery = self._encoders[:k].copy(), self._battery[:k].copy()
        index = [rr.TimeColumn("step", sequence=steps), rr.TimeColumn("sim_time", duration=times)]
        xy = self._poses[:k, :, :2].copy()
        translation = np.concatenate([xy, np.zeros((k, n, 1))], axis=2)
        quaternion = _yaw_quaternions(self._poses[:k, :, 2])
        start = np.concatenate([(xy[0] if self._trail_from is None else self._trail_from)[None],
                                xy[:-1]])
        trail = np.full((k, n, 2, 3), _TRAIL_Z_M)
        trail[:, :, 0, :2] = start
        trail[:, :, 1, :2] = xy
        for i in range(n):
            robot = f"robots/{robot_name(i)}"
            send(f"{robot}/pose", index, rr.Transform3D.columns(
                translation=translation[:, i], quaternion=quaternion[:, i]))
            send(f"{robot}/trail", index, rr.LineStrips3D.columns(strips=trail[:, i]))
            send(f"{robot}/speed", index, rr.Scalars.columns(scalars=speed[:, i]))
            if not self.sensors:
                continue
            send(f"{robot}/battery", index, rr.Scalars.columns(scalars=battery[:, i]))
            send(f"{robot}/sensors/line", index, rr.Scalars.columns(scalars=line[:, i]))
            send(f"{robot}/sensors/ir", index, rr.Scalars.columns(scalars=ir[:, i]))
            send(f"{robot}/sensors/encoders", index,
                 rr.Scalars.columns(scalars=encoders[:, i]))
        self._send_bearings(steps, times)
        self._send_state(steps, times)
        self._trail_from = self._latest_xy = xy[-1]
        self._rows = 0

    def _send_state(self, steps: np.ndarray, times: np.ndarray) -> None:
        for (robot, name), (rows, values) in self._state.items():
            if not rows:
                continue
            r = np.asarray(rows)
            entity = f"robots/{robot_name(robot)}/state/{rr.escape_entity_path_part(name)}"
            self._stream.send_columns(
                entity, [rr.TimeColumn("step", sequence=steps[r]),
                         rr.TimeColumn("sim_time", duration=times[r])],
                rr.Scalars.columns(scalars=np.asarray(values)))
            rows.clear()
            values.clear()

    def _send_bearings(self, steps: np.ndarray, times: np.ndarray) -> None:
        if not self._bearing_rows:
            return
        n = self.n_robots
        rows = np.asarray(self._bearing_rows)
        pairs = np.asarray(self._bearing_pairs)
        values = np.asarray(self._bearing_values, dtype=float)
        order = np.argsort(pairs, kind="stable")  # keeps each pair's rows in time order
        rows, pairs, values = rows[order], pairs[order], values[order]
        cuts = np.flatnonzero(np.diff(pairs)) + 1
        for group in np.split(np.arange(len(pairs)), cuts):
            pair = int(pairs[group[0]])
            i, j = divmod(pair, n)
            entity = f"robots/{robot_name(i)}/bearings/{robot_name(j)}"
            if pair not in self._bearing_series:
                self._bearing_series.add(pair)
                self._stream.log(entity, rr.SeriesPoints(
                    names=f"{robot_name(i)} sees {robot_name(j)}", colors=robot_color(j),
                    marker_sizes=2.0),
                    static=True)
            r = rows[group]
            self._stream.send_columns(
                entity,
                [rr.TimeColumn("step", sequence=steps[r]),
                 rr.TimeColumn("sim_time", duration=times[r])],
                rr.Scalars.columns(scalars=values[group]),
            )
        self._bearing_rows.clear()
        self._bearing_pairs.clear()
        self._bearing_values.clear()

    # --- events ------------------------------------------------------------------------

    def _at(self, step: int, sim_time_s: float) -> None:
        self._check_open()
        self._stream.set_time("step", sequence=step)
        self._stream.set_time("sim_time", duration=sim_time_s)

    def log_event(self, step: int, sim_time_s: float, text: str, robot: int | None = None) -> None:
        """A line in the event log: ``events``, or ``events/R<k>`` for robot index ``robot``."""
        self._at(step, sim_time_s)
        entity = "events" if robot is None else f"events/{robot_name(robot)}"
        self._stream.log(entity, rr.TextLog(text, level="INFO"))

    def log_explored_graph(
        self,
        step: int,
        sim_time_s: float,
        robot: int,
        nodes: Mapping[str, tuple[float, float]],
        edges: Sequence[tuple[str, str]],
    ) -> None:
        """Robot ``robot``'s explored graph: node id -> (x, y) in m, and undirected edges.

        Skipped when identical to the graph last logged for this robot.
        """
        key = (tuple(nodes.items()), tuple(edges))
        if self._last_map.get(robot) == key:
            return
        self._last_map[robot] = key
        self._at(step, sim_time_s)
        k = self.graph_scale
        ids = list(nodes)
        self._stream.log(
            f"map/{robot_name(robot)}",
            rr.GraphNodes(ids, positions=[(k * x, -k * y) for x, y in nodes.values()],
                          labels=ids, colors=robot_color(robot)),
            rr.GraphEdges(list(edges), graph_type="undirected"),
        )

    def log_regions(self, step: int, sim_time_s: float,
                    regions: Mapping[int, tuple[float, float, float]]) -> None:
        """The regions robots guard: robot index -> (x m, y m, radius m), drawn as circles
        on the floor in the robots' colours; logged only when they change."""
        if regions == self._regions:
            return
        self._regions = dict(regions)
        self._at(step, sim_time_s)
        turn = np.linspace(0.0, 2.0 * np.pi, 49)
        self._stream.log("regions", rr.LineStrips3D(
            [np.column_stack([x + r * np.cos(turn), y + r * np.sin(turn),
                              np.full_like(turn, 0.003)]) for x, y, r in regions.values()],
            colors=[robot_color(i) for i in regions], radii=0.004))

    def log_state(self, step: int, sim_time_s: float, robot: int, state: str,
                  lane: str = "decision", changes_only: bool = False) -> None:
        """Robot ``robot``'s controller enters ``state`` (a name) in ``lane``
        (``states/R<k>/<lane>``); with ``changes_only``, nothing is logged while the
        state stays the same."""
        if changes_only and self._last_state.get((robot, lane)) == state:
            return
        self._last_state[(robot, lane)] = state
        self._at(step, sim_time_s)
        self._stream.log(f"states/{robot_name(robot)}/{lane}", rr.StateChange(state=state))

    def log_matrix(self, step: int, sim_time_s: float, robot: int, markdown: str) -> None:
        """The incidence matrix robot ``robot`` carries, as a markdown document."""
        self._at(step, sim_time_s)
        self._stream.log(f"matrices/{robot_name(robot)}",
                         rr.TextDocument(markdown, media_type=rr.MediaType.MARKDOWN))

    def log_beacon(self, step: int, sim_time_s: float, vertex: str, text: str) -> None:
        """The contents of the beacon at ``vertex`` (the beacon's own id), as text."""
        self._at(step, sim_time_s)
        self._stream.log(f"beacons/{rr.escape_entity_path_part(vertex)}", rr.TextDocument(text))

    def log_radio(
        self,
        step: int,
        sim_time_s: float,
        edges: Sequence[tuple[int, int]],
        beliefs: Mapping[int, str] | None = None,
        truth: str | Mapping[int, str] | None = None,
        *,
        fixed: Mapping[str, tuple[float, float]] | None = None,
        fixed_links: Sequence[tuple[int, str]] = (),
        tethers: Mapping[int, int] | None = None,
    ) -> None:
        """The radio graph (robot index pairs in range), drawn at the robots' positions.

        ``fixed``: radio nodes that are no robots (a base station), by name, at (x, y) (m),
        and ``fixed_links`` the (robot, fixed node) pairs in range. ``tethers``: each
        robot's tether parent (a robot index, or -1 for the first fixed node), drawn as
        thick links over the arena. With ``beliefs`` (robot -> its current answer, e.g. whether the team is
        biconnected) and ``truth`` (the ground-truth answer: one for the team, or one per
        robot), nodes are green where the belief equals the truth, red where it differs,
        grey without a belief.
        """
        self._at(step, sim_time_s)
        n = self.n_robots
        for a, b in edges:
            if not (0 <= a < n and 0 <= b < n):
                raise ValueError(f"log_radio: edge ({a}, {b}) names a robot outside 0..{n - 1}")
        beliefs = dict(beliefs or {})
        ids = [robot_name(i) for i in range(n)]
        labels = [f"{ids[i]}: {beliefs[i]}" if i in beliefs else ids[i] for i in range(n)]
        colors = _belief_colors(n, beliefs, truth)
        xy = self._positions()
        fixed = dict(fixed or {})
        pairs = [(ids[a], ids[b]) for a, b in edges] + [(ids[a], f) for a, f in fixed_links]
        # who hears whom is topology: the graph view lays it out by forces, so robots that
        # stand together keep their labels apart (radio/links draws it over the arena)
        self._stream.log("radio/graph",
                         rr.GraphNodes([*ids, *fixed], labels=[*labels, *fixed],
                                       colors=[*colors, *([_ROOT_COLOR] * len(fixed))]),
                         rr.GraphEdges(pairs, graph_type="undirected"))
        if xy is not None:
            z = ROBOT_HEIGHT_M + 0.01
            where = {ids[i]: xy[i] for i in range(n)} | {f: np.asarray(p) for f, p in fixed.items()}
            self._stream.log("radio/links", rr.LineStrips3D(
                [[(*where[a], z), (*where[b], z)] for a, b in pairs],
                colors=(60, 140, 255, 200), radii=0.003))
            if tethers is not None:
                first = next(iter(fixed), None)
                ends = [(ids[i], ids[p] if p >= 0 else first) for i, p in tethers.items()
                        if p >= 0 or first is not None]
                self._stream.log("radio/tethers", rr.LineStrips3D(
                    [[(*where[a], z + 0.005), (*where[b], z + 0.005)] for a, b in ends],
                    colors=[robot_color(int(a[1:]) - 1) for a, _ in ends], radii=0.012))
        if truth is not None or beliefs:
            self._stream.log("radio/truth", rr.TextDocument(_truth_text(ids, beliefs, truth)))

    def _positions(self) -> np.ndarray | None:
        """(N, 2) latest logged robot positions (m), buffered or sent; None before any."""
        if self._rows:
            return self._poses[self._rows - 1, :, :2].copy()
        return self._latest_xy

    def log_video(self, path: str | Path, frame_times_s: Sequence[float]) -> None:
        """Add a finished video file (``camera/video``, rerun's video asset) and, on the
        ``sim_time`` timeline, a reference to each of its frames (``camera``): frame k is
        shown from simulated time ``frame_times_s[k]`` on."""
        self._check_open()
        asset = rr.AssetVideo(path=path)
        self._stream.log("camera/video", asset, static=True)
        stamps = asset.read_frame_timestamps_nanos()
        if len(stamps) != len(frame_times_s):
            raise MjswarmError(f"video {path} has {len(stamps)} frames, the run drew "
                               f"{len(frame_times_s)}")
        self._stream.send_columns(
            "camera",
            [rr.TimeColumn("sim_time", duration=np.asarray(frame_times_s, float))],
            rr.VideoFrameReference.columns_nanos(stamps),
        )
        self._stream.log("camera", rr.VideoFrameReference.from_fields(
            video_reference="camera/video"), static=True)

    # --- lifetime ----------------------------------------------------------------------

    def _check_open(self) -> None:
        if self._closed:
            raise RuntimeError(f"recorder for {self.path} is closed")

    def close(self) -> None:
        """Send buffered ticks, flush and finish the file. Closing twice is harmless."""
        if self._closed:
            return
        self._send_ticks()
        self._stream.flush()
        self._stream.disconnect()
        self._closed = True

    def __enter__(self) -> Self:
        return self

    def __exit__(self, *exc_info) -> None:
        self.close()


def graph_scale(vertices, bounds_m: tuple[float, float, float, float]) -> float:
    """Graph-view units per metre: :data:`GRAPH_SPACING` units between the closest two of
    ``vertices`` ((x, y) in m; None: a 20th of the larger side of ``bounds_m`` stands
    for that distance)."""
    xy = None if vertices is None else np.array(list(vertices), float).reshape(-1, 2)
    if xy is not None and len(xy) > 1:
        d = np.hypot(*(xy[:, None] - xy[None]).transpose(2, 0, 1))
        closest = float(d[d > 1e-9].min()) if (d > 1e-9).any() else 1.0
    else:
        low, high = np.array(bounds_m[:2], float), np.array(bounds_m[2:], float)
        closest = float(max((high - low).max(), 1.0)) / 20.0
    return GRAPH_SPACING / closest


def top_down_eye(bounds_m: tuple[float, float, float, float], aspect: float = 1.35,
                 margin_m: float = 0.3) -> rrb.EyeControls3D:
    """A camera straight above the middle of ``bounds_m`` (m), x to the right and y up,
    high enough that the area and ``margin_m`` around it fill a view ``aspect`` times as
    wide as it is tall (rerun's 3-D view sees :data:`_FOV_Y_DEG` degrees vertically)."""
    low, high = np.array(bounds_m[:2], float), np.array(bounds_m[2:], float)
    centre = (low + high) / 2.0
    half_w, half_h = (high - low) / 2.0 + margin_m
    height = max(half_h, half_w / aspect) / np.tan(np.radians(_FOV_Y_DEG) / 2.0)
    return rrb.EyeControls3D(
        position=(centre[0], centre[1], height), look_target=(centre[0], centre[1], 0.0),
        eye_up=(0.0, 1.0, 0.0))


def graph_bounds(bounds_m: tuple[float, float, float, float], scale: float,
                 margin_m: float = 0.3) -> rrb.VisualBounds2D:
    """What a graph view shows: ``bounds_m`` (m) and ``margin_m`` around them, in graph
    units (``scale`` per metre, y negated as the graphs are logged)."""
    x0, y0, x1, y1 = bounds_m
    return rrb.VisualBounds2D(x_range=[scale * (x0 - margin_m), scale * (x1 + margin_m)],
                              y_range=[-scale * (y1 + margin_m), -scale * (y0 - margin_m)])


def _truth_text(ids: list[str], beliefs: Mapping[int, str],
                truth: str | Mapping[int, str] | None) -> str:
    """The radio truth panel: each robot's belief, with the truth (one for the team, or
    one per robot)."""
    if isinstance(truth, Mapping):
        return "\n".join(f"{ids[i]}: {beliefs.get(i, '-')} (truth: {truth.get(i, '-')})"
                         for i in range(len(ids)))
    lines = [] if truth is None else [f"truth: {truth}"]
    return "\n".join(lines + [f"{ids[i]}: {beliefs[i]}" for i in sorted(beliefs)])


def _belief_colors(n: int, beliefs: Mapping[int, str],
                   truth: str | Mapping[int, str] | None) -> list:
    """Each robot's colour in the radio graph: its own without a ``truth``; else green
    where its belief equals the truth, red where it differs, grey without a belief."""
    if truth is None:
        return [robot_color(i) for i in range(n)]
    truths = dict(truth) if isinstance(truth, Mapping) else dict.fromkeys(range(n), truth)
    return [_NO_BELIEF_COLOR if i not in beliefs
            else _AGREE_COLOR if beliefs[i] == truths.get(i) else _DISAGREE_COLOR
            for i in range(n)]


def _map_views(robots: list[str], frame) -> list:
    """Each robot's map over its incidence matrix, one tab each (all maps in one view
    above :data:`MAP_TAB_LIMIT` robots), every graph in the arena's ``frame``."""
    if len(robots) > MAP_TAB_LIMIT:
        return [rrb.GraphView(name="maps", origin="/map", visual_bounds=frame)]
    return [rrb.Vertical(rrb.GraphView(name=f"map {r}", origin=f"/map/{r}",
                                       visual_bounds=frame),
                         rrb.TextDocumentView(name=f"incidence matrix {r}",
                                              origin=f"/matrices/{r}"),
                         name=r, row_shares=[3, 2]) for r in robots]


def _series_views(robots: list[str], maps: bool, sensors: bool) -> rrb.Tabs:
    """The time series: controller state and telemetry (state first in runs with maps),
    speeds, and the sensors when recorded."""
    def plot(name: str, leaf: str) -> rrb.TimeSeriesView:
        return rrb.TimeSeriesView(name=name, origin="/robots",
                                  contents=[f"+ /robots/{r}/{leaf}" for r in robots])

    states = [rrb.StateTimelineView(name="controller state", origin="/states"),
              plot("telemetry", "state/**")]
    return rrb.Tabs(
        *(states if maps else states[::-1]),
        plot("speed (m/s)", "speed"),
        *([plot("line sensors (m)", "sensors/line"),
           plot("IR (m)", "sensors/ir"),
           plot("bearings (rad)", "bearings/**"),
           plot("encoders (rad)", "sensors/encoders"),
           plot("battery (V)", "battery")] if sensors else []),
    )


def _blueprint(bounds_m: tuple[float, float, float, float], n_robots: int,
               trail_window_s: float, radio: bool, sensors: bool,
               video: bool = False, scale: float = 1.0, maps: bool = True) -> rrb.Blueprint:
    """The layout the file opens with, on the ``sim_time`` timeline, following the data
    to its end: on the left the arena seen from above (strips, walls, named vertices,
    robots in their colours with their headings and trails, radio links) over the event
    log; on the right, one tab per robot with its explored graph over the incidence
    matrix it carries (all graphs in one view above :data:`MAP_TAB_LIMIT` robots) and
    the beacons, for runs on an arena (``maps``), and the radio graph, over the time
    series (controller state, speeds, and the sensors when recorded). The blueprint, selection and time panels start
    collapsed (the time panel to its one-line bar)."""
    robots = [robot_name(i) for i in range(n_robots)]
    trail_range = rrb.VisibleTimeRanges(rrb.VisibleTimeRange(
        "sim_time",
        start=rrb.TimeRangeBoundary.cursor_relative(seconds=-trail_window_s),
        end=rrb.TimeRangeBoundary.cursor_relative(),
    ))
    scene = rrb.Spatial3DView(
        name="arena (from above)",
        origin="/",
        contents=["+ /arena/**", "+ /robots/**", "+ /regions"]
        + (["+ /radio/links", "+ /radio/tethers"] if radio else []),
        overrides={f"/robots/{r}/trail": trail_range for r in robots},
        eye_controls=top_down_eye(bounds_m),
        line_grid=rrb.LineGrid3D(visible=False),
    )
    maps = _map_views(robots, graph_bounds(bounds_m, scale)) if maps else []
    radio_views = [rrb.GraphView(name="radio", origin="/radio/graph"),
                   rrb.TextDocumentView(name="radio truth", origin="/radio/truth")]
    beacons = [rrb.TextDocumentView(name="beacons", origin="/beacons")] if maps else []
    graphs = [*maps, *beacons, *(radio_views if radio else [])]
    series = _series_views(robots, bool(maps), sensors)
    if video:
        scene = rrb.Horizontal(scene, rrb.Spatial2DView(name="camera", origin="/camera"))
    return rrb.Blueprint(
        rrb.Horizontal(
            rrb.Vertical(scene, rrb.TextLogView(name="events", origin="/events"),
                         row_shares=[3, 1]),
            rrb.Vertical(rrb.Tabs(*graphs), series, row_shares=[4, 1]) if graphs else series,
            column_shares=[1, 1],
        ),
        rrb.BlueprintPanel(state="collapsed"),
        rrb.SelectionPanel(state="collapsed"),
        rrb.TimePanel(state="collapsed", timeline="sim_time", play_state="following"),
    )


class Recording(LoopFunctions):
    """Records any run of the one loop (:class:`~mjswarm.worlds.loop.Loop`) with ``recorder``:
    every robot's pose, trail and commanded speed per tick, each controller's
    :meth:`~algorithms.robot.Controller.telemetry` (numbers as time series, named states
    such as a role as state lanes ``states/R<k>/<name>``), and the radio graph
    every ``radio_every`` ticks when the world has a radio. Robots off the floor are
    drawn where the world keeps them (the depot). Close the recorder after the run."""

    def __init__(self, recorder: Recorder, radio_every: int = 10) -> None:
        self.recorder = recorder
        self.radio_every = radio_every
        self._contacts = 0

    def after_step(self, loop: Loop) -> None:
        world, rec = loop.world, self.recorder
        step, now = loop.ticks, world.time_s
        poses = world.true_poses()
        state, regions = {}, {}
        for i, c in loop.controllers.items():
            if world.present[i]:
                telemetry = c.telemetry()
                state[i] = {k: v for k, v in telemetry.items() if not isinstance(v, str)}
                for lane, name in telemetry.items():
                    if isinstance(name, str):
                        rec.log_state(step, now, i, name, lane=lane, changes_only=True)
                if "region_radius_m" in telemetry:
                    regions[i] = (telemetry["region_x_m"], telemetry["region_y_m"],
                                  telemetry["region_radius_m"])
        rec.log_tick(step, now, poses, speed=world.commanded_speeds(), state=state)
        rec.log_regions(step, now, regions)
        events = world.contact_events() or []
        for _, i, j in events[self._contacts:]:
            rec.log_event(step, now, contact_event(i, j, poses))
        self._contacts = len(events)
        if world.radio is not None and step % self.radio_every == 0:
            rec.log_radio(step, now, [tuple(e) for e in world.radio.graph().edges])

    def on_event(self, loop: Loop, text: str, robot: int | None) -> None:
        """An experiment's event (:meth:`~mjswarm.worlds.loop.Loop.event`), at the
        current tick."""
        self.recorder.log_event(loop.ticks, loop.world.time_s, text, robot)

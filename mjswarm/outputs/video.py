"""Video of any run, rendered offscreen as the loop runs.

A :class:`Video` loop function draws a frame whenever the simulated time reaches the next
frame's (one every ``speedup / fps`` simulated seconds: ``fps`` frames per second of video,
``speedup`` simulated seconds per video second) and hands it to ``imageio-ffmpeg``'s
writer (its wheel ships ffmpeg): H.264 in an MP4 file. Only the frames the
video needs are rendered.

Two cameras, one look:

* :class:`MujocoCamera` renders the world's MuJoCo scene (arena strips, walls, robots in
  the recording's per-robot colours) from a camera above the area, tilted
  ``CAMERA_TILT_DEG`` off vertical, with MuJoCo's offscreen renderer, without shadows,
  reflections or skybox (on Mesa's software GL they cost two thirds of a frame: 50 ms
  against 14 ms for arena2 at 640x480). MuJoCo picks its GL
  backend when it is first imported; ``mjswarm`` sets ``MUJOCO_GL=egl`` (Mesa's headless
  EGL) unless the user chose one. When no backend works, :class:`MjswarmError` says so in
  one line.
* :class:`PlotCamera` draws kinematic point worlds (no MuJoCo scene) with matplotlib:
  the same colours, discs of the Spark V's size with a heading tick.

Both draw each robot's trail (its positions at the last ``TRAIL_FRAMES`` frames) and the
marks the loop functions give (e.g. vertices whose beacon has been dropped). Each camera
maps floor points to pixels (``to_pixels``), so every frame is then written over the same
way, to read without the README: the title and simulated time; radio links (when given);
vertex names (the arena's, from the MuJoCo model); each robot's name, and its note (e.g.
its role) when given, beside it; a scale bar on the floor; and a legend: each robot's
colour and name (robots off the floor are listed as "in depot" or "docked at base"),
the marks and the links.
"""

from __future__ import annotations

import math
import os
import warnings
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path

import imageio_ffmpeg
import numpy as np
from PIL import Image, ImageDraw, ImageFont

import mjswarm
from mjswarm.errors import MjswarmError, one_line
from mjswarm.core.contacts import robot_name
from mjswarm.outputs.recording import robot_color
from mjswarm.outputs.video_format import DEFAULT_SPEEDUP, FPS, HEIGHT_PX, WIDTH_PX
from mjswarm.worlds.loop import Loop, LoopFunctions, Scene
#: The overview camera's tilt from looking straight down (degrees).
CAMERA_TILT_DEG = 20.0
#: Vertical field of view of the overview camera (degrees; MuJoCo's free camera default).
FOVY_DEG = 45.0
#: Margin around the framed area, as a fraction of its size.
MARGIN = 0.12
#: Frames of trail drawn behind each robot.
TRAIL_FRAMES = 90
#: Height of trails and marks above the floor (m).
OVERLAY_Z_M = 0.006
MARK_RGBA = (0.95, 0.75, 0.1, 1.0)
#: Radius of a mark on the floor, as a fraction of the framed width (at least 4 cm).
MARK_RADIUS = 0.015
#: Colour of radio links (RGB).
LINK_RGB = (40, 90, 220)
#: Height of the band at the top of every frame, which holds the title and time (pixels).
TITLE_PX = 24
#: Robots the legend lists by name; the rest are counted.
LEGEND_ROBOTS = 12
#: Lengths a scale bar may have (m); it takes the longest within a quarter of the framed
#: width.
SCALE_BARS_M = (0.1, 0.2, 0.5, 1.0, 2.0, 5.0, 10.0, 20.0)
#: Render passes the overview does without (each costs a pass of Mesa's software GL).
NO_RENDER_FLAGS = ("mjRND_SHADOW", "mjRND_REFLECTION", "mjRND_SKYBOX")

#: A frame-rendering function: poses (N, 3), trails (per robot an (M, 2) array, m),
#: marks ((x, y) points, m) -> an RGB frame (H, W, 3) uint8; with ``to_pixels`` (floor
#: points (M, 2) in m -> pixel columns and rows (M, 2)) and ``labels`` (name -> floor
#: point, m: the places each frame names).
Camera = Callable[[np.ndarray, Sequence[np.ndarray], Sequence[tuple[float, float]]], np.ndarray]


class MujocoCamera:
    """Offscreen frames of a simulation's MuJoCo scene framing ``bounds_m``
    ``(x_min, y_min, x_max, y_max)``. Recolours each robot's geoms to its recording
    colour (visual only: colours and materials take no part in physics or sensing)."""

    def __init__(self, sim, bounds_m: Sequence[float], width: int = WIDTH_PX,
                 height: int = HEIGHT_PX) -> None:
        import mujoco

        from mjswarm.arena.builder import VERTEX_SITE_PREFIX

        self._mujoco = mujoco
        self.sim = sim
        model = sim.model
        for g in np.flatnonzero(sim.geom_robot >= 0):
            model.geom_rgba[g] = np.array(robot_color(int(sim.geom_robot[g]))) / 255.0
            model.geom_matid[g] = -1
        model.vis.global_.offwidth = max(model.vis.global_.offwidth, width)
        model.vis.global_.offheight = max(model.vis.global_.offheight, height)
        try:
            with warnings.catch_warnings():  # a failing backend also warns; one line says it
                warnings.simplefilter("ignore")
                self.renderer = mujoco.Renderer(model, height, width, max_geom=20_000)
        except Exception as exc:  # noqa: BLE001 - any GL failure is the same to the user
            if mjswarm.GL_PROBLEM:  # switched off so that mujoco imports (see mjswarm)
                raise MjswarmError(f"cannot render video: {mjswarm.GL_PROBLEM}; set "
                                   "MUJOCO_GL=egl (Mesa's headless EGL) or unset it") from None
            backend = os.environ.get("MUJOCO_GL", "(default)")
            raise MjswarmError(f"cannot render video: no working OpenGL backend "
                               f"(MUJOCO_GL={backend}; MuJoCo reads it when first imported, "
                               f"so set it before importing mujoco): {one_line(exc)}") from None
        self.option = mujoco.MjvOption()
        self.option.geomgroup[:] = 1  # the bodies and the floor are collision geoms (group 3)
        # rangefinder rays would be drawn as short yellow strokes, like the beacon marks
        self.option.flags[mujoco.mjtVisFlag.mjVIS_RANGEFINDER] = 0
        self.camera = _overview(mujoco.MjvCamera(), bounds_m, width / height)
        self.mark_radius_m = max(0.04, MARK_RADIUS * (bounds_m[2] - bounds_m[0]))
        self.size_px = (width, height)
        mujoco.mj_forward(model, sim.data)
        self.labels = {model.site(k).name.removeprefix(VERTEX_SITE_PREFIX):
                       tuple(sim.data.site_xpos[k, :2]) for k in range(model.nsite)
                       if model.site(k).name.startswith(VERTEX_SITE_PREFIX)}

    def to_pixels(self, xy_m) -> np.ndarray:
        """Pixel columns and rows of floor points (M, 2) (m): the free camera's
        perspective (MuJoCo's: the eye ``distance`` behind ``lookat``, ``FOVY_DEG``)."""
        c = self.camera
        az, el = math.radians(c.azimuth), math.radians(c.elevation)
        forward = np.array([math.cos(el) * math.cos(az), math.cos(el) * math.sin(az),
                            math.sin(el)])
        up = np.array([-math.sin(el) * math.cos(az), -math.sin(el) * math.sin(az),
                       math.cos(el)])
        right = np.cross(forward, up)
        xy = np.asarray(xy_m, float).reshape(-1, 2)
        d = np.column_stack([xy, np.zeros(len(xy))]) - (np.array(c.lookat) - c.distance
                                                         * forward)
        width, height = self.size_px
        focal = height / 2.0 / math.tan(math.radians(FOVY_DEG) / 2.0)
        depth = d @ forward
        return np.column_stack([width / 2.0 + focal * (d @ right) / depth,
                                height / 2.0 - focal * (d @ up) / depth])

    def __call__(self, poses, trails, marks) -> np.ndarray:
        mujoco, r = self._mujoco, self.renderer
        r.update_scene(self.sim.data, self.camera, self.option)
        scene = r.scene
        for flag in NO_RENDER_FLAGS:  # a third of the time on software GL, same picture
            scene.flags[getattr(mujoco.mjtRndFlag, flag)] = 0
        eye = np.eye(3).ravel()
        for i, trail in enumerate(trails):
            rgba = np.array(robot_color(i), np.float32) / 255.0
            for a, b in zip(trail[:-1], trail[1:]):
                if scene.ngeom >= scene.maxgeom:
                    break
                g = scene.geoms[scene.ngeom]
                mujoco.mjv_initGeom(g, mujoco.mjtGeom.mjGEOM_LINE, np.zeros(3), np.zeros(3),
                                    eye, rgba)
                mujoco.mjv_connector(g, mujoco.mjtGeom.mjGEOM_LINE, 3.0,
                                     np.array([a[0], a[1], OVERLAY_Z_M]),
                                     np.array([b[0], b[1], OVERLAY_Z_M]))
                scene.ngeom += 1
        for x, y in marks:
            if scene.ngeom >= scene.maxgeom:
                break
            mujoco.mjv_initGeom(scene.geoms[scene.ngeom], mujoco.mjtGeom.mjGEOM_CYLINDER,
                                np.array([self.mark_radius_m, self.mark_radius_m, 0.002]),
                                np.array([x, y, OVERLAY_Z_M]), eye,
                                np.array(MARK_RGBA, np.float32))
            scene.ngeom += 1
        return r.render()

    def close(self) -> None:
        self.renderer.close()


def _overview(camera, bounds_m: Sequence[float], aspect: float):
    """A free camera above the centre of ``bounds_m``, tilted ``CAMERA_TILT_DEG`` towards
    +y, far enough that the whole area (plus ``MARGIN``) fits the frame."""
    x0, y0, x1, y1 = bounds_m
    span_x, span_y = (x1 - x0) * (1 + 2 * MARGIN), (y1 - y0) * (1 + 2 * MARGIN)
    half_fov = math.radians(FOVY_DEG) / 2.0
    needed = max(span_y, span_x / aspect, 0.5)  # the vertical span the view must hold
    camera.distance = needed / (2.0 * math.tan(half_fov)) * (1.0 + math.sin(
        math.radians(CAMERA_TILT_DEG)))
    camera.lookat[:] = ((x0 + x1) / 2.0, (y0 + y1) / 2.0, 0.0)
    camera.azimuth = 90.0  # looking along +y: x to the right
    camera.elevation = -(90.0 - CAMERA_TILT_DEG)
    return camera


class PlotCamera:
    """Frames of a bodiless world drawn with matplotlib (top view of ``bounds_m``)."""

    def __init__(self, bounds_m: Sequence[float], radius_m: float = 0.075,
                 width: int = WIDTH_PX, height: int = HEIGHT_PX) -> None:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        self._plt = plt
        self.radius_m = radius_m
        dpi = 100
        self.figure = plt.figure(figsize=(width / dpi, height / dpi), dpi=dpi)
        self.axes = self.figure.add_axes((0.08, 0.1, 0.6, 0.8))  # the legend goes right
        x0, y0, x1, y1 = bounds_m
        mx, my = (x1 - x0) * MARGIN + 0.2, (y1 - y0) * MARGIN + 0.2
        self.limits = (x0 - mx, x1 + mx, y0 - my, y1 + my)
        self.labels: dict[str, tuple[float, float]] = {}

    def to_pixels(self, xy_m) -> np.ndarray:
        """Pixel columns and rows of floor points (M, 2) (m) on the last frame drawn."""
        px = self.axes.transData.transform(np.asarray(xy_m, float).reshape(-1, 2))
        return np.column_stack([px[:, 0], self.figure.bbox.height - px[:, 1]])

    def __call__(self, poses, trails, marks) -> np.ndarray:
        ax = self.axes
        ax.clear()
        ax.set_xlim(*self.limits[:2])
        ax.set_ylim(*self.limits[2:])
        ax.set_aspect("equal", adjustable="box")
        ax.set_xlabel("x (m)")
        ax.set_ylabel("y (m)")
        for x, y in marks:
            ax.plot(x, y, marker="o", color=MARK_RGBA, markersize=8)
        for i, (trail, pose) in enumerate(zip(trails, poses)):
            color = np.array(robot_color(i)) / 255.0
            if len(trail) > 1:
                ax.plot(trail[:, 0], trail[:, 1], color=color, linewidth=1.2)
            ax.add_patch(self._plt.Circle(pose[:2], self.radius_m, color=color))
            tip = pose[:2] + 1.6 * self.radius_m * np.array([math.cos(pose[2]),
                                                               math.sin(pose[2])])
            ax.plot([pose[0], tip[0]], [pose[1], tip[1]], color="black", linewidth=1.0)
        self.figure.canvas.draw()
        return np.asarray(self.figure.canvas.buffer_rgba())[..., :3].copy()

    def close(self) -> None:
        self._plt.close(self.figure)


class Video(LoopFunctions):
    """Writes the run as it goes to ``path`` (an MP4 file; the caller may have chosen a
    temporary name, so the container is given explicitly).

    Args:
        path: where the video goes.
        bounds_m: ``(x_min, y_min, x_max, y_max)`` of the area to frame (m); the camera
            (:func:`camera_for` the loop's world) is made when the loop starts.
        speedup: simulated seconds per second of video.
        fps: frames per second of video.
        title: written on every frame before the time.

    What else a frame shows comes from the other loop functions' scenes
    (:meth:`~mjswarm.worlds.loop.LoopFunctions.scene`): points to mark (with what they
    are, in the legend), radio links, a word per robot written after its name.
    """

    def __init__(self, path: str | Path, bounds_m: Sequence[float],
                 speedup: float = DEFAULT_SPEEDUP, fps: int = FPS, title: str = "") -> None:
        if not (math.isfinite(speedup) and speedup > 0):
            raise MjswarmError(f"video speed-up must be a positive number, got {speedup}")
        self.path, self.bounds_m, self.speedup, self.fps = Path(path), bounds_m, speedup, fps
        self.camera: Camera | None = None
        self.title = title
        #: simulated time (s) of each frame drawn so far
        self.frame_times_s: list[float] = []
        self._next_s = 0.0
        self._trails: list[list[tuple[float, float]]] = []
        self._writer = None
        self._font = ImageFont.load_default(size=15)
        self._small = ImageFont.load_default(size=12)

    @property
    def frame_interval_s(self) -> float:
        """Simulated seconds between two frames."""
        return self.speedup / self.fps

    def initialize(self, loop: Loop) -> None:
        self.camera = camera_for(loop.world, self.bounds_m)
        self._trails = [[] for _ in range(loop.world.n)]
        self._frame(loop)

    def after_step(self, loop: Loop) -> None:
        if loop.world.time_s + 1e-9 >= self._next_s:
            self._frame(loop)

    def _frame(self, loop: Loop) -> None:
        world = loop.world
        poses = world.true_poses()
        for i, trail in enumerate(self._trails):
            if world.present[i]:
                trail.append((float(poses[i, 0]), float(poses[i, 1])))
                del trail[:-TRAIL_FRAMES]
            else:
                trail.clear()
        scenes = loop.scenes()
        marks = [xy for scene in scenes for xy in scene.marks]
        image = self.camera(poses, [np.array(t).reshape(-1, 2) for t in self._trails], marks)
        picture = Image.fromarray(image)
        self._annotate(ImageDraw.Draw(picture), world, poses, scenes)
        frame = np.ascontiguousarray(np.asarray(picture))
        if self._writer is None:  # the frame size is known now
            self._writer = imageio_ffmpeg.write_frames(
                str(self.path), (frame.shape[1], frame.shape[0]), fps=self.fps,
                codec="libx264", pix_fmt_out="yuv420p", macro_block_size=16,
                output_params=["-f", "mp4"], ffmpeg_log_level="error")
            self._writer.send(None)
        self._writer.send(frame)
        self.frame_times_s.append(world.time_s)
        self._next_s = len(self.frame_times_s) * self.frame_interval_s

    def _annotate(self, draw: ImageDraw.ImageDraw, world, poses: np.ndarray,
                  scenes: Sequence[Scene]) -> None:
        """Links, vertex and robot names, scale bar, legend and title over a frame."""
        to_pixels = self.camera.to_pixels
        links = [link for scene in scenes for link in scene.links]
        for a, b in links:
            draw.line([tuple(p) for p in to_pixels([a, b])], fill=LINK_RGB, width=2)
        for name, (col, row) in zip(self.camera.labels,
                                    to_pixels(list(self.camera.labels.values()))):
            draw.text((col + 5, row - 14), name, fill=(90, 90, 90), font=self._small)
        notes = next((list(sc.notes) for sc in scenes if sc.notes is not None), [""] * world.n)
        on_floor = np.flatnonzero(world.present)
        for i, (col, row) in zip(on_floor, to_pixels(poses[on_floor, :2])):
            draw.text((col + 9, row - 8), f"{robot_name(i)} {notes[i]}".strip(), fill="black",
                      font=self._small, stroke_width=2, stroke_fill="white")
        self._scale_bar(draw)
        self._legend(draw, world, notes, [sc.marks_label for sc in scenes if sc.marks_label],
                     bool(links))
        text = f"{self.title}  t = {world.time_s:7.1f} s  ({self.speedup:g}x)".strip()
        draw.rectangle((0, 0, draw.im.size[0], TITLE_PX), fill=(255, 255, 255))
        draw.text((8, 4), text, fill=(0, 0, 0), font=self._font)

    def _scale_bar(self, draw: ImageDraw.ImageDraw) -> None:
        """A bar of round length on the floor below the framed area's lower left corner,
        named below."""
        x0, y0, x1, y1 = self.bounds_m
        length = max([m for m in SCALE_BARS_M if m <= (x1 - x0) / 4.0] or SCALE_BARS_M[:1])
        y = y0 - 0.6 * MARGIN * max(y1 - y0, 0.5)
        (a, row_a), (b, row_b) = self.camera.to_pixels([(x0, y), (x0 + length, y)])
        draw.line([(a, row_a), (b, row_b)], fill="black", width=3)
        for col, row in ((a, row_a), (b, row_b)):
            draw.line([(col, row - 5), (col, row + 5)], fill="black", width=2)
        draw.text(((a + b) / 2.0, max(row_a, row_b) + 7), f"{length:g} m", fill="black",
                  font=self._small, anchor="ma", stroke_width=2, stroke_fill="white")

    def _legend(self, draw: ImageDraw.ImageDraw, world, notes: Sequence[str],
                marks: Sequence[str], links: bool) -> None:
        """Each robot's colour and name (and where it is when off the floor), then the
        marks and the radio links, in a box at the top right."""
        entries = []  # (swatch: "dot" or "line", RGB, text)
        for i in range(min(world.n, LEGEND_ROBOTS)):
            where = ("" if world.present[i] else
                     " docked at base" if i in world.docked else " in depot")
            entries.append(("dot", robot_color(i)[:3], f"{robot_name(i)} {notes[i]}".rstrip()
                            + where))
        if world.n > LEGEND_ROBOTS:
            entries.append(("", None, f"... {robot_name(world.n - 1)}: {world.n} robots"))
        for label in marks:
            entries.append(("dot", tuple(int(255 * c) for c in MARK_RGBA[:3]), label))
        if links:
            entries.append(("line", LINK_RGB, "radio link"))
        line_px = 16
        width = 30 + max(self._small.getlength(text) for _, _, text in entries)
        right, top = draw.im.size[0] - 6, TITLE_PX + 6
        left = right - width
        draw.rectangle((left, top, right, top + 6 + line_px * len(entries)), fill="white",
                       outline=(120, 120, 120))
        for k, (swatch, rgb, text) in enumerate(entries):
            row = top + 4 + line_px * k + line_px / 2.0
            if swatch == "dot":
                draw.ellipse((left + 8, row - 5, left + 18, row + 5), fill=rgb)
            elif swatch == "line":
                draw.line((left + 5, row, left + 21, row), fill=rgb, width=2)
            draw.text((left + 26, row), text, fill="black", font=self._small, anchor="lm")

    def close(self) -> None:
        """Finish the file (call once the run is over)."""
        if self._writer is not None:
            self._writer.close()  # ffmpeg finishes the file
            self._writer = None
        if self.camera is not None:
            self.camera.close()
            self.camera = None


def area(points: Sequence[tuple[float, float]]) -> tuple[float, float, float, float]:
    """``(x_min, y_min, x_max, y_max)`` of some points (m): what a camera frames."""
    xy = np.asarray(list(points), float).reshape(-1, 2)
    return (*xy.min(axis=0).tolist(), *xy.max(axis=0).tolist())


def camera_for(world, bounds_m: Sequence[float]) -> Camera:
    """The world's MuJoCo scene when it has one (``world.sim``), else a plot."""
    sim = getattr(world, "sim", None)
    return MujocoCamera(sim, bounds_m) if sim is not None else PlotCamera(bounds_m)


@contextmanager
def filming(video: Video | None, recorder=None) -> Iterator[None]:
    """Finish ``video`` (if any) when the block ends; when it ends normally the video also
    goes into ``recorder`` (:meth:`mjswarm.outputs.recording.Recorder.log_video`)."""
    if video is None:
        yield
        return
    try:
        yield
    finally:
        video.close()
    if recorder is not None:
        recorder.log_video(video.path, video.frame_times_s)

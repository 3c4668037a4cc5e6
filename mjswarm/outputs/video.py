"""Video of any run, rendered offscreen as the loop runs (issue 15).

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
marks the loop functions give (e.g. vertices whose beacon has been dropped), and the
simulated time is written on every frame.
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
from mjswarm.outputs.recording import robot_color
from mjswarm.worlds.loop import Loop, LoopFunctions

#: Frames per second of video.
FPS = 30
#: Default simulated seconds per second of video (a 420 s run lasts 14 s).
DEFAULT_SPEEDUP = 30.0
#: Frame size (pixels).
WIDTH_PX, HEIGHT_PX = 640, 480
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
#: Render passes the overview does without (each costs a pass of Mesa's software GL).
NO_RENDER_FLAGS = ("mjRND_SHADOW", "mjRND_REFLECTION", "mjRND_SKYBOX")

#: A frame-rendering function: poses (N, 3), trails (per robot an (M, 2) array, m),
#: marks ((x, y) points, m) -> an RGB frame (H, W, 3) uint8.
Camera = Callable[[np.ndarray, Sequence[np.ndarray], Sequence[tuple[float, float]]], np.ndarray]


class MujocoCamera:
    """Offscreen frames of a simulation's MuJoCo scene framing ``bounds_m``
    ``(x_min, y_min, x_max, y_max)``. Recolours each robot's geoms to its recording
    colour (visual only: colours and materials take no part in physics or sensing)."""

    def __init__(self, sim, bounds_m: Sequence[float], width: int = WIDTH_PX,
                 height: int = HEIGHT_PX) -> None:
        import mujoco

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
                                np.array([0.04, 0.04, 0.002]),
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
        self.axes = self.figure.add_axes((0.1, 0.1, 0.86, 0.8))
        x0, y0, x1, y1 = bounds_m
        mx, my = (x1 - x0) * MARGIN + 0.2, (y1 - y0) * MARGIN + 0.2
        self.limits = (x0 - mx, x1 + mx, y0 - my, y1 + my)

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
        marks: ``marks()`` gives the points (m) to mark on the next frame, or None.
        title: written on every frame before the time.
    """

    def __init__(self, path: str | Path, bounds_m: Sequence[float],
                 speedup: float = DEFAULT_SPEEDUP, fps: int = FPS,
                 marks: Callable[[], Sequence[tuple[float, float]]] | None = None,
                 title: str = "") -> None:
        if not (math.isfinite(speedup) and speedup > 0):
            raise MjswarmError(f"video speed-up must be a positive number, got {speedup}")
        self.path, self.bounds_m, self.speedup, self.fps = Path(path), bounds_m, speedup, fps
        self.camera: Camera | None = None
        self.marks, self.title = marks, title
        #: simulated time (s) of each frame drawn so far
        self.frame_times_s: list[float] = []
        self._next_s = 0.0
        self._trails: list[list[tuple[float, float]]] = []
        self._writer = None
        self._font = ImageFont.load_default(size=15)

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
        marks = list(self.marks()) if self.marks is not None else []
        image = self.camera(poses, [np.array(t).reshape(-1, 2) for t in self._trails], marks)
        picture = Image.fromarray(image)
        text = f"{self.title}  t = {world.time_s:7.1f} s  ({self.speedup:g}x)".strip()
        draw = ImageDraw.Draw(picture)
        draw.rectangle((0, 0, picture.width, 24), fill=(255, 255, 255))
        draw.text((8, 4), text, fill=(0, 0, 0), font=self._font)
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

    @property
    def frames(self) -> int:
        """Frames written so far."""
        return len(self.frame_times_s)

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

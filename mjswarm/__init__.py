"""mjswarm: embodied, decentralised multi-robot exploration and connectivity on MuJoCo.

The simulator side: world building, sensors, actuation, stepping, radio, beacons,
recording, metrics, CLI and experiment runners. The robots' minds live in the
sibling package :mod:`algorithms`, which never imports MuJoCo.

MuJoCo chooses its OpenGL backend when it is first imported, and its import fails when
``MUJOCO_GL`` names a backend it does not know or whose library is missing. Unless the
user chose one, mjswarm asks for Mesa's headless EGL, so videos render on machines
without a display. A backend that would break MuJoCo's import is switched off instead
(``MUJOCO_GL=disable``) and :data:`GL_PROBLEM` says why: every command works, and only a
video, the one thing that needs OpenGL, is refused with that line.
"""

import ctypes.util
import os

#: MUJOCO_GL values MuJoCo accepts on Linux (mujoco/rendering/classic/gl_context.py).
MUJOCO_GL_VALUES = ("", "enable", "enabled", "on", "true", "1", "glfw", "glx", "egl",
                    "osmesa", "disable", "disabled", "off", "false", "0")
#: Backends whose missing library makes ``import mujoco`` itself fail.
MUJOCO_GL_LIBRARY = {"egl": "EGL", "osmesa": "OSMesa"}


def _gl_problem(value: str) -> str | None:
    """Why ``MUJOCO_GL=value`` would break ``import mujoco``, or None."""
    value = value.lower().strip()
    if value not in MUJOCO_GL_VALUES:
        return f"MUJOCO_GL={value} is not a backend MuJoCo knows"
    library = MUJOCO_GL_LIBRARY.get(value)
    if library and ctypes.util.find_library(library) is None:
        return f"MUJOCO_GL={value} needs lib{library}, which is not installed"
    return None


#: Why the user's OpenGL backend was switched off (None: it was not).
GL_PROBLEM = None if "MUJOCO_GL" not in os.environ else _gl_problem(os.environ["MUJOCO_GL"])
if GL_PROBLEM:
    os.environ["MUJOCO_GL"] = "disable"
os.environ.setdefault("MUJOCO_GL", "egl")

__version__ = "0.2.0"

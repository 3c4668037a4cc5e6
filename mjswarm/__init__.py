"""mjswarm: embodied, decentralised multi-robot exploration and connectivity on MuJoCo.

The simulator side: world building, sensors, actuation, stepping, radio, beacons,
recording, metrics, CLI and experiment runners. The robots' minds live in the
sibling package :mod:`algorithms`, which never imports MuJoCo.

MuJoCo chooses its OpenGL backend when it is first imported; unless the user chose one,
mjswarm asks for Mesa's headless EGL, so videos render on machines without a display.
"""

import os

os.environ.setdefault("MUJOCO_GL", "egl")

__version__ = "0.1.0"

"""mjswarm: embodied, decentralised multi-robot exploration and connectivity on MuJoCo.

The simulator side: world building, sensors, actuation, stepping, radio, beacons,
recording, metrics, CLI and experiment runners. The robots' minds live in the
sibling package :mod:`algorithms`, which never imports MuJoCo.
"""

__version__ = "0.1.0"

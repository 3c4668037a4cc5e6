"""The simulation core: the robot model, world building, stepping, ray casting, sensors and the radio."""

#: The physics tiers: ``"dynamic"``, MuJoCo's contact physics; ``"kinematic"``, the robots
#: move by their wheels' kinematics (:mod:`mjswarm.core.kinematic`).
PHYSICS = ("dynamic", "kinematic")

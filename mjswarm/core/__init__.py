"""The simulation core: the robot model, world building, stepping, ray casting, sensors and the radio."""

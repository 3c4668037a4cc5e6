"""Which beacon each robot may read, handed to the world before the robots sense.

The stations (:class:`~mjswarm.experiments.stations.StationService`) decide which
vertex's beacon a robot may read: the one whose centre it stands on, when they let it
read there. :class:`BeaconHand` asks them at the start of every tick, after their grants,
for every robot on the floor, and hands the answers to the world
(:meth:`~mjswarm.worlds.sparkworld.SparkWorld.hand_beacons`), which reads nothing else.
"""

from __future__ import annotations

from mjswarm.worlds.loop import Loop, LoopFunctions


class BeaconHand(LoopFunctions):
    """Hands ``world`` the vertex whose beacon each robot may read this tick, as
    ``stations.beacon_at`` says; it runs after the stations' ``before_step``."""

    def __init__(self, world, stations) -> None:
        self.world, self.stations = world, stations

    def before_step(self, loop: Loop) -> None:
        beacon_at = self.stations.beacon_at
        self.world.hand_beacons({i: v for i in self.world.active()
                                 if (v := beacon_at(i)) is not None})

"""A robot that only navigates: its :class:`~.navigator.Navigator` as a controller."""

from __future__ import annotations

from algorithms.navigation.navigator import Navigator
from algorithms.navigation.percept import percept
from algorithms.robot import Command, Controller, Observation


class Navigating(Controller):
    """Feeds the robot's own line, IR and encoder readings to ``navigator`` and drives
    with the ``(v, omega)`` it answers (the caller tells the navigator where to go)."""

    def __init__(self, navigator: Navigator) -> None:
        self.navigator = navigator

    def step(self, observation: Observation) -> Command:
        nav = self.navigator
        v, w = nav.update(percept(observation.line_m, observation.ir_m,
                                  observation.encoder_rad, nav.line_filter))
        return Command(v, w)

"""Shared fixtures: small worlds built directly from primitives."""

from __future__ import annotations

import pytest

from mjswarm.core.simulation import Simulation
from mjswarm.core.world import Pose2D, world_spec


@pytest.fixture
def one_robot() -> Simulation:
    """One robot at the origin facing +x on a bare 4 m x 4 m floor."""
    return Simulation(world_spec([Pose2D(0.0, 0.0, 0.0)], margin_m=2.0))

"""Shared fixtures: small scenarios that run in well under a second."""

from __future__ import annotations

from pathlib import Path

import pytest

import cosim
from cosim.scenario import Scenario

REPO = Path(__file__).resolve().parent.parent
SHARED_DATA = REPO.parent / "shared" / "data"

SMALL = {
    "scenario.duration_s": 3.0,
    "world.size_m": [12.0, 12.0],
    "world.shelf_count": 4,
    "robots.count": 3,
    "lidar.beams": 90,
    "robots.driver": "waypoints",
}


@pytest.fixture
def small_scenario() -> Scenario:
    """A 12 m x 12 m hall, 4 shelves, 3 robots, 90-beam lidar, 3 s."""
    return cosim.load_scenario("warehouse-random", overrides=SMALL)

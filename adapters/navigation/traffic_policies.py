"""cosim's own traffic policies, registered in ``cosim.traffic`` as a plugin's are.

- ``none``: every robot plans for itself (A* + DWA by default), two-way everywhere;
- ``lanes``: the same, with aisles up to :data:`LANE_WIDTH_M` wide one-way, neighbouring
  aisles in opposite directions (derived from the building's map; fleet managers draw such
  lanes, e.g. Open-RMF's one-way lanes); planners charge more for a step against a lane,
  and robots in a lane are traffic to follow rather than obstacles to plan round;
- ``pibt``: the fleet manager moves every robot over a grid of robot-sized places with
  those one-way aisles and a one-way floor, one step of Priority Inheritance with
  Backtracking at a time (Okumura et al., Artificial Intelligence 310, 2022; see
  :mod:`adapters.navigation.fleet_traffic`).
"""

from __future__ import annotations

from typing import ClassVar

import numpy as np

from adapters.mocap.tracking import tracked_robots
from adapters.naming import robot_name
from adapters.navigation.contract import TrafficContext
from adapters.navigation.fleet_traffic import FleetTraffic
from adapters.navigation.layers import lanes_on
from adapters.navigation.places import GAP_M, FleetPlaces
from cosim.core.errors import ConfigError
from cosim.scenario.model import Scenario
from models.arrays import BoolArray, UInt8Array

LANE_WIDTH_M = 2.5
"""Aisles up to this wide are one-way (m); two robots pass in wider."""


class NoTraffic:
    """Every robot plans for itself on what it knows; no lanes, no fleet manager."""

    name: ClassVar[str] = "none"

    def __init__(self, context: TrafficContext) -> None:
        self.lanes: UInt8Array | None = None
        self.manager: FleetTraffic | None = None


class LaneTraffic:
    """One-way lanes in the narrow aisles; every robot still plans for itself."""

    name: ClassVar[str] = "lanes"

    def __init__(self, context: TrafficContext) -> None:
        # drawn on the building's map by the fleet manager, as Open-RMF's lanes are
        self.lanes: UInt8Array | None = lanes_on(context.layers[0], context.truth(), LANE_WIDTH_M)
        self.manager: FleetTraffic | None = None


class PibtTraffic:
    """A fleet manager moves every robot place by place (PIBT), on one-way aisles and floor."""

    name: ClassVar[str] = "pibt"

    @staticmethod
    def check_scenario(scenario: Scenario) -> None:
        """Refuse robots that cannot localize to within the places' gap (see below)."""
        names = [robot_name(i) for i in range(scenario.robots.count)]
        check_localization(scenario, np.isin(names, tracked_robots(scenario, names)))

    def __init__(self, context: TrafficContext) -> None:
        self.lanes: UInt8Array | None = None  # robots do not plan: the manager moves them
        places = FleetPlaces(
            context.static,
            lanes_on(context.static, context.truth(), LANE_WIDTH_M),
            context.starts_m,
            context.radius_m,
        )
        self.manager: FleetTraffic | None = FleetTraffic(places)


def check_localization(scenario: Scenario, tracked: BoolArray) -> None:
    """Refuse the fleet manager for robots that cannot tell where they are to within the gap.

    The places are :data:`GAP_M` apart beyond the robots' bodies, and each robot drives to
    them on its own pose estimate. Robots localizing on their own maps (``mapping.enabled``)
    or on drifting odometry alone (``odometry.drift`` > 0) are off by more: in fleet50 the
    maps put them 0.15-0.3 m off on average (50 robots mostly see each other), and with
    traffic "pibt" robots touched 5 times in 2 seeds x 120 s (9 in 4 with drift 0.02)
    where motion capture gave 0 contacts and 0 goals given up.

    Args:
        scenario: the run's scenario.
        tracked: (n,) robots localizing by measured poses (motion capture).

    Raises:
        ConfigError: when a robot not tracked localizes by mapping or drifting odometry.
    """
    if tracked.all():
        return
    if scenario.mapping.enabled:
        how = "[mapping] enabled = true (robots localize on their own maps, 0.15-0.3 m off)"
    elif scenario.odometry.drift > 0:
        how = (
            f"[odometry] drift = {scenario.odometry.drift:g} (robots localize by odometry "
            "alone, whose error grows without bound)"
        )
    else:
        return
    raise ConfigError(
        f"{scenario.source}: [navigation] traffic = 'pibt' with {how}: expected every robot "
        f"localized to within centimetres ({int((~tracked).sum())} of {len(tracked)} are not "
        "tracked): the fleet manager keeps robots "
        f"{GAP_M:g} m apart on neighbouring places and trusts their poses. Set "
        "navigation.traffic = 'none' (each robot plans on what it knows) or track the robots "
        "by motion capture (mocap.source = 'simulated')"
    )

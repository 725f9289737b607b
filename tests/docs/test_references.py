"""The generated references cover everything a user can set, read or run.

Each reference page has its tests beside its generator's, in ``tests/cosim/reference``;
here, what the pages rely on elsewhere.
"""

from __future__ import annotations

import re

import cosim
from cosim.scenario import dump_scenario


def test_the_resolved_scenario_lists_the_sections_in_reference_order():
    text = dump_scenario(cosim.load_scenario("warehouse-random"))
    order = re.findall(r"^\[(\w+)\]$", text, flags=re.M)
    assert order[:6] == ["scenario", "world", "robots", "lidar", "odometry", "network"]
    assert order[-1] == "record"

"""People in bags: /humans/markers carries SUMO's people as tables/humans records them."""

import math

import numpy as np
import pytest

import cosim

from .conftest import mcap_file, read_mcap

pytestmark = pytest.mark.slow


def test_people_markers_in_the_bag_sit_where_the_humans_table_has_them(tmp_path):
    scenario = cosim.load_scenario(
        "warehouse-humans",
        {"scenario.duration_s": 6.0, "humans.workers": 4, "humans.forklifts": 1},
    )
    result = cosim.run(scenario, out=tmp_path / "run")
    bag = read_mcap(mcap_file(tmp_path / "run" / "bag"))
    assert bag.types["/humans/markers"] == "visualization_msgs/msg/MarkerArray"
    humans = result.tables["humans"]
    checked = 0
    ids: dict[str, set[int]] = {}
    for message in bag.messages["/humans/markers"]:
        stamp = message.markers[0].header.stamp
        t_s = stamp.sec + stamp.nanosec * 1e-9
        assert message.markers[0].action == 3  # DELETEALL first
        shown = message.markers[1:]
        rows = humans[np.isclose(humans["t_s"], t_s)]
        if rows.empty:
            assert not shown  # before SUMO's first step nobody is there
            continue
        assert len(shown) == len(rows)
        for _, row in rows.iterrows():
            near = [
                m
                for m in shown
                if math.hypot(m.pose.position.x - row["x_m"], m.pose.position.y - row["y_m"]) < 1e-6
            ]
            assert len(near) == 1
            marker = near[0]
            assert marker.type == (1 if row["kind"] == "forklift" else 3)  # CUBE / CYLINDER
            ids.setdefault(row["id"], set()).add(marker.id)
            checked += 1
    assert checked > 100
    assert "forklift_0" in ids
    assert all(len(marker_ids) == 1 for marker_ids in ids.values())  # an id per person


def test_a_run_without_people_has_no_people_markers(tmp_path):
    scenario = cosim.load_scenario("warehouse-rows", {"scenario.duration_s": 2.0})
    cosim.run(scenario, out=tmp_path / "run")
    bag = read_mcap(mcap_file(tmp_path / "run" / "bag"))
    assert "/humans/markers" not in bag.types

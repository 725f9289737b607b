"""People in bags: /humans/markers carries SUMO's people where tables/humans records them.

The bag is read back with the `mcap` packages (an independent reader, not cosim's own).
"""

import math
from collections import defaultdict
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory

import cosim

pytestmark = pytest.mark.slow

HUMANS = {"scenario.duration_s": 10.0, "humans.workers": 3, "humans.forklifts": 1}
DELETEALL, ADD = 3, 0
CUBE, CYLINDER = 1, 3


def _topics(bag_dir: Path) -> tuple[dict[str, str], dict[str, list[tuple[int, object]]]]:
    """Schema name per topic, and every message as (log time in ns, decoded message)."""
    (path,) = sorted(bag_dir.glob("*.mcap"))
    types: dict[str, str] = {}
    messages: dict[str, list[tuple[int, object]]] = defaultdict(list)
    with path.open("rb") as stream:
        reader = make_reader(stream, decoder_factories=[DecoderFactory()])
        for schema, channel, message, decoded in reader.iter_decoded_messages(log_time_order=True):
            types[channel.topic] = schema.name
            messages[channel.topic].append((message.log_time, decoded))
    return types, messages


@pytest.fixture(scope="module")
def people_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("people") / "run"
    result = cosim.run(cosim.load_scenario("warehouse-humans", HUMANS), out=out)
    types, messages = _topics(out / "bag")
    return result, types, messages


def _ns(t_s: float) -> int:
    return round(t_s * 1e9)


@pytest.mark.slow
def test_people_markers_sit_where_the_humans_table_has_everyone_at_the_same_stamps(people_run):
    result, types, messages = people_run
    assert types["/humans/markers"] == "visualization_msgs/msg/MarkerArray"
    humans: pd.DataFrame = result.tables["humans"]
    by_stamp = {_ns(t): rows for t, rows in humans.groupby("t_s", sort=True)}
    humans_cfg = result.scenario.humans
    diameter = 2 * humans_cfg.worker_radius_m
    length, width = humans_cfg.forklift_size_m
    marker_ids: dict[str, set[int]] = defaultdict(set)
    stamps = []
    for log_ns, message in messages["/humans/markers"]:
        clear, *shown = message.markers
        stamp_ns = clear.header.stamp.sec * 10**9 + clear.header.stamp.nanosec
        assert stamp_ns == log_ns
        stamps.append(stamp_ns)
        assert (clear.action, clear.ns) == (DELETEALL, "humans")
        rows = by_stamp.get(stamp_ns)
        if rows is None:
            assert stamp_ns < min(by_stamp)  # before SUMO's first step nobody is there
            assert not shown
            continue
        assert len(shown) == len(rows)
        for marker in shown:
            assert (marker.ns, marker.header.frame_id, marker.action) == ("humans", "map", ADD)
            assert marker.header.stamp == clear.header.stamp
        for row in rows.itertuples():
            (marker,) = [
                m
                for m in shown
                if math.hypot(m.pose.position.x - row.x_m, m.pose.position.y - row.y_m) < 1e-9
            ]
            q = marker.pose.orientation
            yaw = 2 * math.atan2(q.z, q.w)
            assert math.isclose(math.cos(yaw), math.cos(row.yaw_rad), abs_tol=1e-9)
            assert math.isclose(math.sin(yaw), math.sin(row.yaw_rad), abs_tol=1e-9)
            scale = (marker.scale.x, marker.scale.y, marker.scale.z)
            if row.kind == "forklift":
                assert marker.type == CUBE
                assert scale[:2] == pytest.approx((length, width))
                assert marker.color.r > 0.8 and marker.color.g > 0.7 > marker.color.b  # yellow
            else:
                assert marker.type == CYLINDER
                assert scale == pytest.approx((diameter, diameter, 1.7))
                assert marker.color.r > 0.8 and 0.35 < marker.color.g < 0.7  # orange
                assert marker.color.b < 0.3
            assert marker.pose.position.z == pytest.approx(marker.scale.z / 2)  # on the floor
            marker_ids[row.id].add(marker.id)
    # every sample of the table has its markers, at the same stamp
    assert set(by_stamp) <= set(stamps)
    assert humans["id"].nunique() == 4 and set(marker_ids) == set(humans["id"])
    # one marker id per person for the whole run, no two people sharing one
    assert all(len(ids) == 1 for ids in marker_ids.values())
    assert len({next(iter(ids)) for ids in marker_ids.values()}) == len(marker_ids)


def test_people_markers_are_published_at_the_pose_sampling_tick(people_run):
    _, _, messages = people_run
    people = [log_ns for log_ns, _ in messages["/humans/markers"]]
    clock = [log_ns for log_ns, _ in messages["/clock"]]
    assert people == clock
    assert np.all(np.diff(people) > 0)


def test_a_run_without_people_has_no_people_markers(tmp_path):
    scenario = cosim.load_scenario("warehouse-rows", {"scenario.duration_s": 2.0})
    cosim.run(scenario, out=tmp_path / "run")
    types, messages = _topics(tmp_path / "run" / "bag")
    assert "/world/markers" in types and messages["/clock"]
    assert "/humans/markers" not in types

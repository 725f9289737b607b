"""Robots mapping in a run: drift corrected, maps shared, quality recorded, maps exported."""

from pathlib import Path

import numpy as np
import pytest

import cosim
from adapters.world.files import read_map
from tests.conftest import SMALL

MAPPING = {
    **SMALL,
    "robots.driver": "navigation",
    "lidar.beams": 180,
    "scenario.duration_s": 40.0,
    "mapping.enabled": True,
    "odometry.drift": 0.03,
}


def _run(tmp_path: Path | None = None, **overrides):
    scenario = cosim.load_scenario("warehouse-random", overrides={**MAPPING, **overrides})
    return cosim.run(scenario, out=tmp_path)


@pytest.fixture(scope="module")
def mapped(tmp_path_factory):
    return _run(tmp_path_factory.mktemp("runs") / "mapped")


def test_scan_matching_keeps_the_estimate_within_a_third_of_odometrys_error(mapped):
    s = mapped.summary
    assert s["map_ate_odom_m"] > 0.1
    assert s["map_ate_m"] <= s["map_ate_odom_m"] / 3
    assert s["collisions"] == 0
    assert s["map_updates"] > 20 and s["map_matched_share"] > 0.9


def test_map_quality_has_a_row_per_robot_and_the_fleet_every_period(mapped):
    quality = mapped.tables["map_quality"]
    assert set(quality.robot) == {"robot_1", "robot_2", "robot_3", "fleet"}
    assert sorted(set(quality.t_s)) == [5.0 * k for k in range(1, 9)]
    fleet = quality[quality.robot == "fleet"]
    assert fleet.coverage.is_monotonic_increasing or fleet.coverage.iloc[-1] > 0.3
    assert ((quality.iou >= 0) & (quality.iou <= 1)).all()
    final = fleet.iloc[-1]
    assert final.iou >= final.iou_strict


def test_final_maps_are_written_as_map_server_maps(mapped):
    for name in ("robot_1", "robot_3", "fleet"):
        grid = read_map(mapped.out / "maps" / f"{name}.yaml")
        assert (grid.data == 100).any() and (grid.data == 0).any()
    robot = read_map(mapped.out / "maps" / "robot_1.yaml")
    assert robot.resolution_m == 0.05


def test_navigation_plans_on_each_robots_own_map_and_localizes_by_its_estimate(mapped):
    matches = mapped.tables["scan_matches"]
    assert (matches.error_m < 0.3).all()
    navigation = mapped.tables["navigation"]
    assert (navigation.event == "arrived").sum() >= 3


@pytest.mark.slow
def test_sharing_under_total_loss_degrades_to_each_robots_own_map(tmp_path):
    # both under total loss: the robots layer's poses (on with mapping) are lost too
    total_loss = {"network.loss_model": "bernoulli", "network.loss_prob": 1.0}
    alone = _run(tmp_path / "alone", **total_loss)
    lost = _run(tmp_path / "lost", **{"mapping.share": "scans", **total_loss})
    assert lost.summary["map_merges"] == 0 and lost.summary["map_share_messages"] > 0
    for name in ("robot_1", "robot_2", "robot_3"):
        assert np.array_equal(
            read_map(lost.out / "maps" / f"{name}.yaml").data,
            read_map(alone.out / "maps" / f"{name}.yaml").data,
        )


@pytest.mark.parametrize("mode", ["scans", "maps"])
def test_shared_evidence_widens_every_robots_map(tmp_path, mode, mapped):
    shared = _run(tmp_path, **{"mapping.share": mode})
    assert shared.summary["map_merges"] > 0 and shared.summary["map_share_bytes"] > 0
    merges = shared.tables["map_merges"]
    assert set(merges.kind) == {mode[:-1]} and (merges.delay_s >= 0).all()
    coverage = lambda r: r.tables["map_quality"].groupby("robot", observed=True).coverage.last()  # noqa: E731
    mine, theirs = coverage(mapped), coverage(shared)
    for robot in ("robot_1", "robot_2", "robot_3"):
        assert theirs[robot] > mine[robot]


@pytest.mark.slow
def test_the_same_seed_gives_the_same_maps_and_tables(tmp_path):
    first = _run(tmp_path / "a", **{"mapping.share": "maps", "network.profile": "wifi_degraded"})
    second = _run(tmp_path / "b", **{"mapping.share": "maps", "network.profile": "wifi_degraded"})
    for name, frame in first.deterministic_tables().items():
        assert second.deterministic_tables()[name].equals(frame), name
    for name in first.maps:
        assert np.array_equal(first.maps[name].data, second.maps[name].data)


@pytest.mark.slow
def test_robots_recognise_their_loops_in_a_run_as_far_as_their_settings_search(tmp_path):
    loops = {"mapping.loop_closure": True, "scenario.duration_s": 60.0}
    closed = _run(tmp_path / "a", **loops)
    revisits = closed.summary["map_loop_closures"] + closed.summary["map_loop_closures_not_needed"]
    assert revisits > 0
    blind = _run(tmp_path / "b", **loops, **{"mapping.loop_search_radius_m": 0.01})
    assert blind.summary["map_loop_closures"] + blind.summary["map_loop_closures_not_needed"] == 0
    assert closed.summary["map_ate_m"] <= closed.summary["map_ate_odom_m"] / 3


@pytest.mark.slow
def test_with_a_robots_layer_the_other_robots_stay_out_of_the_maps():
    from adapters.world.warehouse import scenario_warehouse
    from models.geometry.occupancy import rasterize_boxes
    from models.mapping.quality import dilate

    phantoms = {}
    for layer in (False, True):
        overrides = {
            **MAPPING,
            "robots.count": 6,
            "navigation.robots_layer": layer,
            "scenario.duration_s": 30.0,
            # a seed on which robots without the layer clearly map each other: since A*
            # breaks equal-cost ties by depth (other paths of the same cost), seeds 1, 2
            # and 4 give only 4-9 phantom cells at 30 s (seed 3: 49; before: 57-79 on all
            # four, and seed 2 also 32 with the layer)
            "scenario.seed": 3,
        }
        scenario = cosim.load_scenario("warehouse-random", overrides=overrides)
        fleet = cosim.run(scenario).maps["fleet"]
        (x0, y0), r = fleet.origin_xy_m, fleet.resolution_m
        rows, cols = fleet.data.shape
        truth = rasterize_boxes(
            scenario_warehouse(scenario).boxes, (x0, y0, x0 + cols * r, y0 + rows * r), r
        ).data
        # mapped obstacles more than two cells from any real one: robots mapped as walls
        phantoms[layer] = int(((fleet.data == 100) & ~dilate(dilate(truth == 100))).sum())
    assert phantoms[False] > 20 and phantoms[True] == 0

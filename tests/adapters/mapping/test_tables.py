import math

import numpy as np
import pytest

import cosim
from adapters.mapping.geometry import map_geometry
from adapters.mapping.mapper import MappingAdapter
from adapters.mapping.tables import (
    FLEET,
    MAP_MERGES,
    MAP_QUALITY,
    MATCH_COLUMNS,
    MERGE_COLUMNS,
    QUALITY_COLUMNS,
    SCAN_MATCHES,
    MappingRecords,
)
from cosim.core.recorder import Recorder
from cosim.recording.dataframes import table_frame
from cosim.runner.assembly import assemble
from models.geometry.occupancy import UNKNOWN, OccupancyGrid
from models.world.warehouse import Warehouse
from tests.conftest import SMALL

SPECS = (MAP_QUALITY, SCAN_MATCHES, MAP_MERGES)
UNITS = {"_s": "(s)", "_m": "(m)", "_rad": "(rad)"}


def test_the_mapping_adapter_declares_the_tables_it_writes():
    assert MappingAdapter.tables == SPECS
    assert [spec.name for spec in SPECS] == ["map_quality", "scan_matches", "map_merges"]


def test_the_tables_have_the_documented_columns():
    assert QUALITY_COLUMNS == (
        "t_s",
        "robot",
        "coverage",
        "iou",
        "accuracy",
        "ate_m",
        "ate_odom_m",
        "iou_strict",
    )
    assert MATCH_COLUMNS == (
        "t_s",
        "robot",
        "x_m",
        "y_m",
        "yaw_rad",
        "error_m",
        "odom_error_m",
        "score",
        "matched",
    )
    assert MERGE_COLUMNS == ("t_s", "robot", "source", "kind", "bytes", "delay_s", "cells")


@pytest.mark.parametrize("spec", SPECS, ids=lambda s: s.name)
def test_every_column_with_a_unit_in_its_name_says_it_and_categoricals_are_columns(spec):
    for column, meaning in spec.columns.items():
        for suffix, unit in UNITS.items():
            if column.endswith(suffix):
                assert unit in meaning, (spec.name, column)
    assert "robot" in spec.categorical
    assert set(spec.categorical) <= set(spec.columns)
    assert set(spec.volatile) <= set(spec.columns)


@pytest.fixture(scope="module")
def world() -> Warehouse:
    scenario = cosim.load_scenario("warehouse-random", SMALL)
    return assemble(scenario, names=["world"]).run.service(Warehouse)


def records_of(world: Warehouse) -> MappingRecords:
    return MappingRecords(Recorder(), ["robot_1", "robot_2"], world, map_geometry(world, 0.1))


def test_a_map_update_records_the_estimates_and_odometrys_errors_against_the_truth(world):
    records = records_of(world)
    records.update(2_000_000_000, 1, (3.0, 4.0, 0.5), (0.0, 0.0), (6.0, 8.0), 0.8, True)
    records.update(3_000_000_000, 1, (1.0, 0.0, 0.5), (0.0, 0.0), (0.0, 2.0), 0.3, False)
    rows = table_frame(records.matches)
    assert list(rows.t_s) == [2.0, 3.0]
    assert list(rows.robot) == ["robot_2", "robot_2"]
    assert list(rows.error_m) == [5.0, 1.0]
    assert list(rows.odom_error_m) == [10.0, 2.0]
    assert list(rows.matched) == [True, False]
    summary = records.summary()
    assert summary["map_updates"] == 2
    assert summary["map_matched_share"] == 0.5
    assert summary["map_ate_m"] == pytest.approx(math.sqrt((25 + 1) / 2))
    assert summary["map_ate_odom_m"] == pytest.approx(math.sqrt((100 + 4) / 2))


def test_a_merge_records_its_delay_from_the_senders_stamp(world):
    records = records_of(world)
    records.merge(1_250_000_000, 0, "robot_2", "scan", 900, 1_000_000_000, 12)
    records.merge(2_000_000_000, 1, "robot_1", "map", 300, 1_500_000_000, 40)
    rows = table_frame(records.merges)
    assert list(rows.delay_s) == [0.25, 0.5]
    assert list(rows.kind) == ["scan", "map"] and list(rows.source) == ["robot_2", "robot_1"]
    assert list(rows.bytes) == [900, 300] and list(rows.cells) == [12, 40]
    summary = records.summary()
    assert summary["map_merges"] == 2
    assert summary["map_merge_delay_s_mean"] == pytest.approx(0.375)


def test_what_robots_send_is_counted_in_messages_and_bytes(world):
    records = records_of(world)
    records.shared(1000)
    records.shared(24)
    summary = records.summary()
    assert (summary["map_share_messages"], summary["map_share_bytes"]) == (2, 1024)


class _Map:
    """A robot's map as :meth:`MappingRecords.sample` reads it."""

    def __init__(self, cells: np.ndarray) -> None:
        self.cells = cells

    def occupancy(self) -> np.ndarray:
        return self.cells


def test_quality_is_sampled_per_robot_and_for_the_fleet_against_the_truth(world):
    records = records_of(world)
    records.update(0, 0, (0.3, 0.0, 0.0), (0.0, 0.0), (0.0, 0.4), 1.0, True)
    perfect = records.truth.copy()
    blank = np.full_like(perfect, UNKNOWN)
    fleet = OccupancyGrid(0.1, (-1.2, -1.2), perfect)
    records.sample(5_000_000_000, [_Map(perfect), _Map(blank)], fleet)  # type: ignore[list-item]
    rows = table_frame(records.quality).set_index("robot")
    assert list(rows.index) == ["robot_1", "robot_2", FLEET]
    assert (rows.t_s == 5.0).all()
    assert rows.loc["robot_1", ["coverage", "iou", "accuracy", "iou_strict"]].tolist() == [1.0] * 4
    assert rows.loc["robot_2", "coverage"] == 0.0
    assert rows.loc["robot_1", "ate_m"] == pytest.approx(0.3)
    assert math.isnan(rows.loc["robot_2", "ate_m"])  # no update yet
    assert rows.loc[FLEET, "ate_odom_m"] == pytest.approx(0.4)
    summary = records.summary()
    assert (summary["map_coverage"], summary["map_iou"], summary["map_accuracy"]) == (1, 1, 1)


def test_a_run_without_updates_merges_or_samples_reports_none_not_nan(world):
    summary = records_of(world).summary()
    assert summary == {
        "map_coverage": None,
        "map_iou": None,
        "map_accuracy": None,
        "map_iou_strict": None,
        "map_ate_m": None,
        "map_ate_odom_m": None,
        "map_updates": 0,
        "map_matched_share": None,
        "map_share_messages": 0,
        "map_share_bytes": 0,
        "map_merges": 0,
        "map_merge_delay_s_mean": None,
    }

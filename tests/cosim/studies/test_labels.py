"""Axis labels in words and units (cosim.studies.labels)."""

import tomllib
from pathlib import Path

import pytest

from cosim.studies.labels import LABELS, axis_label, short_label, with_unit

STUDIES = Path(__file__).resolve().parents[3] / "studies"


@pytest.mark.parametrize(
    ("column", "label"),
    [
        ("tasks_per_min", "Tasks per minute"),
        ("mean_task_latency_s", "Mean task latency (s)"),
        ("humans_min_distance_m", "Smallest person-robot gap (m)"),
        ("network.latency_ms", "Network latency (ms)"),
        ("network.bandwidth_mbps", "Network bandwidth (Mbit/s)"),
    ],
)
def test_known_columns_get_their_label(column, label):
    assert axis_label(column) == label


@pytest.mark.parametrize(
    ("column", "label"),
    [
        ("humans_max_distance_m", "Humans max distance (m)"),
        ("network.jitter_ms", "Network jitter (ms)"),
        ("lidar.rate_hz", "Lidar rate (Hz)"),
        ("robots.max_speed_mps", "Robots max speed (m/s)"),
        ("picks_per_min", "Picks (per min)"),
        ("network.drop_prob", "Network drop probability"),
        ("replans", "Replans"),
    ],
)
def test_unknown_columns_get_words_and_the_unit_of_their_suffix(column, label):
    assert column not in LABELS
    assert axis_label(column) == label


def test_every_column_a_shipped_study_reports_on_has_a_written_label():
    named = set()
    for path in STUDIES.glob("*.toml"):
        report = tomllib.loads(path.read_text()).get("report", {})
        named |= {report[k] for k in ("x", "hue", "facet") if k in report}
        named |= {m for k in ("metrics", "heatmaps", "loglog") for m in report.get(k, [])}
        named |= {entry["y"] for entry in report.get("timeseries", [])}
    assert named and sorted(named - set(LABELS)) == []


def test_a_short_label_drops_the_unit():
    assert short_label("network.latency_ms") == "Network latency"
    assert short_label("assignment.protocol") == "Assignment protocol"


def test_a_grid_value_is_named_with_the_unit_of_its_key():
    assert with_unit("network.bandwidth_mbps", "1") == "Network bandwidth = 1 Mbit/s"
    assert with_unit("mapping.share", "maps") == "Map sharing = maps"

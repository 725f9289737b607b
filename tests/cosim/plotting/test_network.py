"""The network over a run: deliveries and drops per second by cause, latency percentiles."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from matplotlib.colors import to_rgba
from matplotlib.figure import Figure

from cosim.plotting import network
from cosim.plotting.network import (
    BINS_MAX,
    CAUSE_COLORS,
    PERCENTILES,
    bin_width_s,
    inter_host,
    network_figure,
)
from cosim.plotting.rundata import RunData, load_run


def _messages(*rows: tuple[float, float, str, str, str]) -> pd.DataFrame:
    """Messages: (t_sent_s, t_recv_s, src_host, dst_host, status) each, on topic /t."""
    frame = pd.DataFrame(rows, columns=["t_sent_s", "t_recv_s", "src_host", "dst_host", "status"])
    return frame.assign(topic="/t")


# in the first second: 3 deliveries (10, 20, 30 ms), 1 lost; in the second: 1 delivery
# (40 ms), 1 queue_full, 2 partitioned, 1 of an older run's cause; copies on one host
MESSAGES = _messages(
    (0.1, 0.11, "robot_1", "robot_2", "delivered"),
    (0.2, 0.22, "robot_2", "robot_1", "delivered"),
    (0.3, 0.33, "robot_1", "base", "delivered"),
    (0.4, np.nan, "robot_1", "robot_3", "lost"),
    (1.1, 1.14, "base", "robot_1", "delivered"),
    (1.2, np.nan, "base", "robot_2", "queue_full"),
    (1.3, np.nan, "robot_3", "robot_1", "partitioned"),
    (1.4, np.nan, "robot_3", "robot_2", "partitioned"),
    (1.5, np.nan, "robot_3", "robot_2", "jammed"),
    (0.5, 0.5, "robot_1", "robot_1", "delivered"),
    (1.6, 1.6, "base", "base", "delivered"),
)


@pytest.fixture(scope="module")
def messages_run(waypoint_run: Path) -> RunData:
    """The waypoint run (3 s, messages on their own hosts) with :data:`MESSAGES`."""
    return dataclasses.replace(load_run(waypoint_run), messages=MESSAGES)


@pytest.fixture
def drawn(monkeypatch: pytest.MonkeyPatch) -> list[Figure]:
    figures: list[Figure] = []
    monkeypatch.setattr(network, "save_png", lambda figure, path: figures.append(figure) or path)
    return figures


def test_only_messages_between_two_hosts_count(messages_run: RunData, waypoint_run: Path):
    between = inter_host(messages_run)
    assert len(between) == 9 and (between["src_host"] != between["dst_host"]).all()
    assert inter_host(load_run(waypoint_run)).empty  # waypoints: no message leaves its host
    assert inter_host(dataclasses.replace(messages_run, messages=None)).empty


@pytest.mark.parametrize(
    ("duration_s", "width_s"), [(0.5, 1.0), (BINS_MAX, 1.0), (BINS_MAX + 1, 2.0), (3600.0, 6.0)]
)
def test_bins_are_a_second_wide_unless_the_run_is_longer_than_600_s(duration_s, width_s):
    assert bin_width_s(duration_s) == width_s


def test_three_panels_over_send_time_label_their_rates_and_latency_in_units(
    messages_run: RunData, drawn, tmp_path
):
    assert network_figure(messages_run, tmp_path / "n.png") == tmp_path / "n.png"
    ok, drop, latency = drawn[0].axes[:3]
    assert ok.get_ylabel() == "delivered (msg/s)"
    assert drop.get_ylabel() == "dropped (msg/s)"
    assert latency.get_ylabel() == "latency (ms)"
    assert latency.get_xlabel() == "send time (s), 1 s bins"
    assert (
        drawn[0].get_suptitle().endswith("network (ideal), 9 inter-host messages, 44.4 % delivered")
    )


def test_deliveries_per_second_are_drawn_at_the_middle_of_each_bin(messages_run, drawn, tmp_path):
    network_figure(messages_run, tmp_path / "n.png")
    (line,) = drawn[0].axes[0].get_lines()
    np.testing.assert_allclose(line.get_xdata(), [0.5, 1.5])
    np.testing.assert_allclose(line.get_ydata(), [3.0, 1.0])


def test_drops_are_stacked_by_cause_in_delivery_status_order_unknown_causes_grey(
    messages_run, drawn, tmp_path
):
    network_figure(messages_run, tmp_path / "n.png")
    drop = drawn[0].axes[1]
    causes = [c.get_label() for c in drop.containers]
    assert causes == ["lost", "queue_full", "partitioned", "jammed"]
    heights = {c.get_label(): [bar.get_height() for bar in c] for c in drop.containers}
    assert heights == {
        "lost": [1.0, 0.0], "queue_full": [0.0, 1.0], "partitioned": [0.0, 2.0],
        "jammed": [0.0, 1.0],
    }  # fmt: skip
    bottoms = [bar.get_y() for bar in drop.containers[3]]
    assert bottoms == [1.0, 3.0]  # on top of the others
    colors = {c.get_label(): c[0].get_facecolor() for c in drop.containers}
    assert colors["lost"] == pytest.approx(to_rgba(CAUSE_COLORS["lost"]))
    assert colors["jammed"] == pytest.approx(to_rgba("0.5"))
    legend = drop.get_legend()
    assert legend is not None and legend.get_title().get_text() == "dropped: cause"


def test_latency_is_drawn_as_p50_p95_p99_of_each_bin_s_deliveries_in_ms(
    messages_run, drawn, tmp_path
):
    network_figure(messages_run, tmp_path / "n.png")
    lines = drawn[0].axes[2].get_lines()
    assert [line.get_label() for line in lines] == [f"p{p}" for p in PERCENTILES]
    p50, p95, _ = lines
    np.testing.assert_allclose(p50.get_ydata(), [20.0, 40.0])  # ms
    np.testing.assert_allclose(p95.get_ydata(), [29.0, 40.0])


def test_a_network_without_drops_or_delay_says_so_instead_of_drawing_nothing(
    messages_run, drawn, tmp_path
):
    instant = _messages(
        (0.1, 0.1, "robot_1", "robot_2", "delivered"),
        (0.2, 0.2, "robot_2", "robot_1", "delivered"),
    )
    network_figure(dataclasses.replace(messages_run, messages=instant), tmp_path / "n.png")
    texts = [t.get_text() for ax in drawn[0].axes for t in ax.texts]
    assert texts == ["no inter-host message dropped", "every delivery took 0 ms"]
    assert drawn[0].get_suptitle().endswith("2 inter-host messages, 100.0 % delivered")


def test_the_figure_is_written_as_a_png(messages_run: RunData, tmp_path: Path):
    path = network_figure(messages_run, tmp_path / "figures" / "network.png")
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"

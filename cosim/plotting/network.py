"""The network over a run: messages delivered and dropped (by cause), latency percentiles.

Only messages between two hosts count: a message to a subscriber on its own host never
crosses the network model (it is delivered at once).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import numpy.typing as npt
import pandas as pd
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from cosim.plotting.canvas import save_png
from cosim.plotting.rundata import RunData
from models.arrays import FloatArray, IntArray
from models.network.delivery import DeliveryStatus

StrArray = npt.NDArray[np.str_]

BINS_MAX = 600
"""Most time bins drawn; runs longer than this many seconds get wider bins."""
PERCENTILES = (50, 95, 99)
PERCENTILE_COLORS = ("#1f77b4", "#ff7f0e", "#d62728")
CAUSE_COLORS = {
    DeliveryStatus.LOST.value: "#d62728",
    DeliveryStatus.QUEUE_FULL.value: "#ff7f0e",
    DeliveryStatus.OUT_OF_RANGE.value: "#9467bd",
    DeliveryStatus.PARTITIONED.value: "#8c564b",
}
"""Colour of each cause of a drop; causes of older runs not listed here are drawn grey."""


def inter_host(run: RunData) -> pd.DataFrame:
    """The run's messages between two different hosts (empty if none or no table)."""
    messages = run.messages
    if messages is None:
        return pd.DataFrame()
    return messages[messages["src_host"] != messages["dst_host"]]


def bin_width_s(duration_s: float) -> float:
    """Width of the time bins (s): 1 s, or wider for runs longer than :data:`BINS_MAX` s."""
    return float(max(1, math.ceil(duration_s / BINS_MAX)))


def network_figure(run: RunData, png_path: Path) -> Path:
    """Draw the network over time (run with inter-host messages) to ``png_path``.

    Three panels over time bins of the send time (s): messages delivered per second,
    messages dropped per second stacked by cause (``lost``, ``queue_full``,
    ``out_of_range``, ``partitioned``), and the p50/p95/p99 one-way latency (ms) of the
    messages delivered in each bin.

    Raises:
        ExportError: naming the path if the file cannot be written.
    """
    messages = inter_host(run)
    end_s = max(float(run.track.t_s[-1]), float(messages["t_sent_s"].max()))
    width = bin_width_s(end_s)
    bins = np.floor(messages["t_sent_s"].to_numpy(np.float64) / width).astype(np.int64)
    edges: FloatArray = np.arange(int(bins.max()) + 1, dtype=np.float64) * width
    status = messages["status"].to_numpy(dtype=str)
    delivered = status == DeliveryStatus.DELIVERED.value
    latency_ms = (messages["t_recv_s"] - messages["t_sent_s"]).to_numpy(np.float64) * 1e3

    figure = Figure(figsize=(10.0, 7.0), layout="constrained")
    ax_ok, ax_drop, ax_lat = figure.subplots(3, 1, sharex=True)
    rate = np.bincount(bins[delivered], minlength=len(edges)) / width
    ax_ok.plot(edges + width / 2, rate, color="#2ca02c", lw=1.2)
    ax_ok.set_ylabel("delivered (msg/s)")
    _dropped(ax_drop, bins[~delivered], status[~delivered], edges, width)
    _latency(ax_lat, bins[delivered], latency_ms[delivered], edges, width)
    ax_lat.set_xlabel(f"send time (s), {width:g} s bins")
    ax_lat.set_xlim(0, edges[-1] + width)
    for ax in (ax_ok, ax_drop, ax_lat):
        ax.set_ylim(bottom=0)
        ax.grid(True, alpha=0.3)
    figure.suptitle(
        f"{run.title}: network ({run.scenario.network.profile}), {len(messages):,} inter-host "
        f"messages, {delivered.mean() * 100:.1f} % delivered",
        fontsize=11,
    )
    return save_png(figure, png_path)


def _dropped(ax: Axes, bins: IntArray, causes: StrArray, edges: FloatArray, width: float) -> None:
    """Drops per second stacked by cause, in the order of :class:`DeliveryStatus`."""
    order = [c.value for c in DeliveryStatus]
    present = sorted(set(causes), key=lambda c: order.index(c) if c in order else len(order))
    bottom = np.zeros(len(edges))
    for cause in present:
        rate = np.bincount(bins[causes == cause], minlength=len(edges)) / width
        color = CAUSE_COLORS.get(cause, "0.5")
        ax.bar(edges, rate, width, bottom=bottom, align="edge", color=color, label=cause, lw=0)
        bottom += rate
    if present:
        ax.legend(title="dropped: cause", fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1))
    else:
        _note(ax, "no inter-host message dropped")
    ax.set_ylabel("dropped (msg/s)")


def _latency(
    ax: Axes, bins: IntArray, latency_ms: FloatArray, edges: FloatArray, width: float
) -> None:
    """Percentiles of the one-way latency of the deliveries in each bin (ms)."""
    grouped = pd.Series(latency_ms).groupby(bins)
    for p, color in zip(PERCENTILES, PERCENTILE_COLORS, strict=True):
        q = grouped.quantile(p / 100)
        ax.plot(edges[q.index] + width / 2, q.to_numpy(), color=color, lw=1.2, label=f"p{p}")
    if not (latency_ms > 0).any():  # the lines lie on the axis
        _note(ax, "every delivery took 0 ms")
    ax.legend(title="one-way, delivered", fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1))
    ax.set_ylabel("latency (ms)")


def _note(ax: Axes, text: str) -> None:
    ax.text(0.5, 0.5, text, transform=ax.transAxes, ha="center", va="center", color="0.4")

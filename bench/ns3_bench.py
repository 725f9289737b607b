"""The ns-3 radio (network.backend = "ns3") against the built-in links backend, same runs.

warehouse-random, 20 s, 4 / 20 / 50 robots serving tasks by the distributed simplex, every
robot broadcasting its state at 10 Hz (the robots layer), 90-beam lidars, no bag: the
whole run's real-time factor with the radio (its process's start left out: 10-15 s once
per run, ns-3's import and template compilation), the radio's own, and the same run on
``links``. Targets (issue 47): 20 robots at least 2x real time, 50 at least 0.5x.
"""

from __future__ import annotations

import importlib.util
import statistics
from typing import Any

import cosim

Result = dict[str, Any]

DURATION_S = 20.0
ROBOTS = (4, 20, 50)
TARGETS = {20: 2.0, 50: 0.5}


def _overrides(robots: int, backend: str) -> dict[str, Any]:
    return {
        "scenario.duration_s": DURATION_S,
        "robots.count": robots,
        "lidar.beams": 90,
        "navigation.robots_layer": True,
        "navigation.robots_layer_hz": 10.0,
        "record.bag": "none",
        "network.backend": backend,
    }


def ns3_radio(repeat: int) -> Result:
    """Per fleet size: real-time factors with ns-3 (start left out) and with links."""
    if importlib.util.find_spec("ns") is None:
        return {"skipped": "the ns3 extra is not installed (make ns3)"}
    out: Result = {"duration_s": DURATION_S, "scenario": "warehouse-random", "targets": TARGETS}
    for n in ROBOTS:
        rtf, radio_rtf, links_rtf, delivered = [], [], [], []
        for _ in range(max(repeat, 1)):
            s = dict(
                cosim.run(cosim.load_scenario("warehouse-random", _overrides(n, "ns3"))).summary
            )
            wall = float(s["wall_time_s"]) - float(s["radio_start_s"])
            rtf.append(DURATION_S / wall)
            radio_rtf.append(DURATION_S / max(float(s["radio_wall_s"]), 1e-9))
            delivered.append(s["radio_delivered"] / max(s["radio_copies"], 1))
            links = dict(
                cosim.run(cosim.load_scenario("warehouse-random", _overrides(n, "links"))).summary
            )
            links_rtf.append(float(links["real_time_factor"]))
        row = {
            "real_time_factor_median": round(statistics.median(rtf), 2),
            "real_time_factor_all": [round(x, 2) for x in rtf],
            "radio_alone_real_time_factor_median": round(statistics.median(radio_rtf), 2),
            "links_real_time_factor_median": round(statistics.median(links_rtf), 2),
            "delivered_fraction_last": round(delivered[-1], 3),
            "radio_start_s_last": round(float(s["radio_start_s"]), 2),
        }
        if n in TARGETS:
            row["meets_target"] = row["real_time_factor_median"] >= TARGETS[n]
        out[f"robots_{n}"] = row
    return out

"""The ns3 backend: refused clearly without ns-3, and with it a real radio in its own process."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import pytest

import cosim
from adapters.network.ns3 import backend as ns3_backend
from cosim.core.errors import ConfigError

# robot_1 talks; robot_2 35 m away, robot_3 66 m away behind a wall, robot_4 64 m away
# past the wall's end, robot_5 150 m away: at 20 dBm, exponent 3 and 40.05 dB at 1 m the
# mean signal is -66, -85 (-75 without the wall), -74 and -85 dBm against -82 detected
ROOM: dict[str, Any] = {
    "scenario.duration_s": 3.0,
    "world.size_m": [240.0, 20.0],
    "world.shelf_count": 0,
    "world.obstacles": [[60.0, 2.0, 61.0, 12.0]],
    "robots.count": 5,
    "robots.placement": "explicit",
    "robots.positions": [[10, 10, 0], [45, 10, 0], [76, 10, 0], [73, 19, 0], [160, 10, 0]],
    "robots.max_speed_mps": 0.05,
    "robots.driver": "navigation",
    "navigation.robots_layer": True,
    "lidar.beams": 90,
    "record.bag": "none",
    "network.backend": "ns3",
    # robots publish their states in the same kernel instant; spread over 50 ms the frames of
    # robots hidden from each other by the wall seldom overlap (with 1 ms they often do)
    "ns3.send_jitter_ms": 50.0,
}


def test_without_ns3_the_backend_is_refused_saying_how_to_install_it(monkeypatch):
    monkeypatch.setattr(ns3_backend, "_installed", lambda: False)
    with pytest.raises(ConfigError, match=r"pip install 'cosim\[ns3\]'"):
        cosim.load_scenario("warehouse-random", {"network.backend": "ns3"})


def test_loading_and_building_a_run_over_ns3_imports_nothing_of_ns3():
    code = (
        "import sys, cosim\n"
        "from cosim.runner.assembly import assemble\n"
        "s = cosim.load_scenario('warehouse-random', {'network.backend': 'ns3'})\n"
        "assemble(s)\n"
        "bad = sorted(m for m in sys.modules if m.split('.')[0] in ('ns', 'cppyy'))\n"
        "assert not bad, bad\n"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr[-2000:]


def test_who_hears_whom_follows_distance_and_walls_without_the_radio_running():
    scenario = cosim.load_scenario("warehouse-random", ROOM)
    from cosim.runner.assembly import assemble

    run = assemble(scenario, names=["network"]).run
    from adapters.network.contract import NetworkView

    up = run.service(NetworkView).up_links(0)
    assert ("robot_1", "robot_2") in up and ("robot_1", "robot_4") in up
    assert ("robot_1", "robot_3") not in up and ("robot_1", "robot_5") not in up


def _run(tmp: Path, name: str, overrides: dict[str, Any]) -> cosim.RunResult:
    return cosim.run(cosim.load_scenario("warehouse-random", overrides), out=tmp / name)


@pytest.mark.slow
def test_delivery_falls_with_distance_and_with_a_wall_in_between(tmp_path, monkeypatch):
    views = []
    start = ns3_backend.Ns3Backend.start

    def keep_view(self, run):
        views.append(self.view)
        start(self, run)

    monkeypatch.setattr(ns3_backend.Ns3Backend, "start", keep_view)
    radio = _run(tmp_path, "room", ROOM).tables["radio"]
    # what a protocol reads: the signal robot_2 last heard robot_1 with, never robot_5
    [view] = views
    assert view.rssi_dbm("robot_2", "robot_1") == pytest.approx(-66.4, abs=1.0)
    assert view.rssi_dbm("robot_5", "robot_1") is None
    heard = (
        radio[radio.src == "robot_1"]
        .groupby("dst", observed=True)
        .status.apply(lambda s: (s == "delivered").mean())
    )
    assert heard["robot_2"] >= 0.9 and heard["robot_4"] >= 0.9
    assert heard["robot_3"] <= 0.1 and heard["robot_5"] == 0.0
    near = radio[(radio.src == "robot_1") & (radio.dst == "robot_2")]
    far = radio[(radio.src == "robot_1") & (radio.dst == "robot_4")]
    assert near.rssi_dbm.mean() > far.rssi_dbm.mean() + 5  # 35 m against 64 m
    lost = radio[(radio.src == "robot_1") & (radio.dst == "robot_3")]
    assert (lost.status == "preamble_detect_failure").mean() > 0.5  # heard, too weak


@pytest.mark.slow
def test_a_run_over_ns3_is_identical_when_run_again(tmp_path):
    small = {
        "scenario.duration_s": 4.0,
        "world.size_m": [16.0, 16.0],
        "world.shelf_count": 6,
        "robots.count": 4,
        "lidar.beams": 90,
        "record.bag": "none",
        "network.backend": "ns3",
        "ns3.fading": "nakagami",
    }
    first = _run(tmp_path, "a", small)
    again = _run(tmp_path, "b", small)
    for name in ("radio", "messages", "tasks", "navigation"):
        pd.testing.assert_frame_equal(
            first.tables[name].drop(columns=["plan_ms"], errors="ignore"),
            again.tables[name].drop(columns=["plan_ms"], errors="ignore"),
        )
    # the second run built its network in the radio the first one left (ns-3 reset): no
    # new process to start, and the same records as a fresh one
    assert again.summary["radio_start_s"] < 3.0
    radio = first.tables["radio"]
    assert len(radio) > 100 and (radio.status == "delivered").mean() > 0.9
    assert np.isfinite(radio[radio.status == "delivered"].rssi_dbm).all()
    assert first.summary["radio_copies"] == len(radio)


@pytest.mark.slow
def test_ns3_aborting_mid_run_ends_the_run_in_one_line_keeping_what_ran(tmp_path, monkeypatch):
    step = ns3_backend.Ns3Backend._step

    def abort_at_one_second(self, now_ns):
        if now_ns >= 1_000_000_000 and self.process is not None:
            self.process.call("abort")
        step(self, now_ns)

    monkeypatch.setattr(ns3_backend.Ns3Backend, "_step", abort_at_one_second)
    from adapters.network.ns3.process import RadioDiedError

    with pytest.raises(RadioDiedError) as died:
        _run(tmp_path, "aborted", {**ROOM, "scenario.duration_s": 5.0})
    said = str(died.value)
    assert "\n" not in said and "SIGABRT" in said
    kept = died.value.kept
    assert kept is not None and 0.9 < kept.summary["sim_time_s"] < 1.1
    assert len(kept.tables["radio"]) > 0


def _delivered(sync: str) -> tuple[list[tuple[int, int]], pd.DataFrame]:
    """robot_1 publishes at 1 ms and 33 ms; (sent, received) at robot_2, and the radio table."""
    from cosim.core.hosts import HostId
    from cosim.core.messages import Twist
    from cosim.runner.assembly import assemble

    scenario = cosim.load_scenario(
        "warehouse-random", {**ROOM, "ns3.sync": sync, "ns3.send_jitter_ms": 0.0}
    )
    assembly = assemble(scenario, names=["network"])
    run = assembly.run
    got: list[tuple[int, int]] = []
    run.bus.advertise("/probe", Twist)
    run.bus.subscribe(
        "/probe", HostId("robot_2"), lambda m, e: got.append((e.t_sent_ns, e.t_recv_ns))
    )
    for _name, adapter in assembly.adapters:
        adapter.start(run)
    for t in (1_000_000, 33_000_000):
        run.kernel.at(t, lambda: run.bus.publish("/probe", Twist(1.0, 0.0), HostId("robot_1")))
    run.kernel.run(100_000_000)
    for _name, adapter in assembly.adapters:
        adapter.finish(run)
    return got, pd.DataFrame(run.recorder.tables["radio"].columns())


@pytest.mark.slow
def test_in_exact_mode_a_message_arrives_when_its_radio_received_it_and_in_windows_after():
    exact, radio = _delivered("exact")
    heard = radio[(radio.dst == "robot_2") & (radio.topic == "/probe")]
    assert [r for _, r in exact] == [round(t * 1e9) for t in heard.t_radio_s]
    assert all(0 < r - s < 2_000_000 for s, r in exact)  # 35 m, a 6 Mbit/s frame: < 2 ms
    windows, _ = _delivered("window")
    assert [r for _, r in windows] == [10_000_000, 40_000_000]  # the windows' ends


@pytest.mark.slow
def test_a_rate_the_standard_does_not_have_is_refused_naming_the_key_and_the_known_ones(tmp_path):
    scenario = cosim.load_scenario(
        "warehouse-random", {**ROOM, "ns3.rate": "Bogus", "scenario.duration_s": 1.0}
    )
    with pytest.raises(ConfigError, match=r"\[ns3\] rate = 'Bogus': not a mode of 80211g") as bad:
        cosim.run(scenario, out=tmp_path / "bogus")
    assert "ErpOfdmRate6Mbps" in str(bad.value)

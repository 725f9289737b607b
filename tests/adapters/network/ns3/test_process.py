"""The radio's process: ns-3 aborting it ends nothing but it, and says why."""

from __future__ import annotations

import numpy as np
import pytest

from adapters.network.ns3.process import (
    RadioDiedError,
    RadioProcess,
    RadioRefusedError,
    acquire,
    release,
)
from adapters.network.ns3.wire import RX_DTYPE

pytestmark = pytest.mark.slow

SETUP = {
    "n_nodes": 2,
    "standard": "80211g",
    "rate": "ErpOfdmRate6Mbps",
    "tx_power_dbm": 20.0,
    "exponent": 3.0,
    "reference_loss_db": 40.05,
    "nakagami": False,
    "detection_dbm": -82.0,
    "walls": [],
    "wall_loss_db": 10.0,
    "seed": 1,
    "run": 1,
}


@pytest.fixture(scope="module")
def radio():
    process = acquire()  # this worker's radio, if a run left one: no new start
    process.call("setup", SETUP)
    yield process
    release(process)


def test_a_refused_request_is_said_and_the_radio_serves_on(radio):
    with pytest.raises(RadioRefusedError, match="rate"):
        radio.call("setup", {**SETUP, "rate": "NoSuchRate"})
    with pytest.raises(RadioRefusedError, match="unknown request"):
        radio.call("dance")
    radio.call("setup", SETUP)
    step = {
        "positions": np.array([[0.0, 0.0], [20.0, 0.0]]),
        "sends": (np.array([1_000_000]), np.array([0]), np.array([42]), np.array([200])),
        "until": 10_000_000,
    }
    rx_bytes, _drops, _took, _now = radio.call("step", step)
    rx = np.frombuffer(rx_bytes, RX_DTYPE)
    assert rx["msg_id"].tolist() == [42] and rx["rx"].tolist() == [1]
    assert 1_000_000 < rx["t_ns"][0] < 2_000_000 and -70 < rx["rssi_dbm"][0] < -50


def test_ns3_aborting_kills_only_its_process_and_the_reason_is_told():
    process = RadioProcess()
    process.call("setup", SETUP)
    with pytest.raises(RadioDiedError, match="SIGABRT") as died:
        process.call("abort")
        process.call("step", {"positions": None, "sends": None, "until": 1})
    assert "ns-3 radio's process ended" in str(died.value)
    assert not process.alive()
    process.close()  # closing a dead one is quiet

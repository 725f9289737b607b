"""The ns-3 radio, in the radio's own process: one 802.11 ad-hoc network of N nodes.

Imported only by :mod:`adapters.network.ns3.child` (importing it imports ns-3: 7-11 s
and about 700 MB). It compiles ``radio.cpp`` with cppyy and drives it: positions, sends at
exact nanoseconds, runs to a time and hands back the records since the last run
(:data:`~adapters.network.ns3.wire.RX_DTYPE`, :data:`~adapters.network.ns3.wire.DROP_DTYPE`).

ns-3 keeps global state (its simulator, node list, random streams, address allocators):
one radio lives in a process at a time, and building a new one resets that state, so the
same seed gives the same records in any process (checked byte for byte). Bad arguments
are refused by the C++ checks as :class:`RadioError`; what ns-3 itself finds wrong aborts
the process, which is why the radio runs in a process of its own.
"""

from __future__ import annotations

from importlib.resources import files
from typing import Any

import cppyy
import numpy as np
from ns import ns  # noqa: F401  (loads ns-3's modules)

from adapters.network.ns3.wire import DROP_DTYPE, RX_DTYPE

cppyy.cppdef(files("adapters.network.ns3").joinpath("radio.cpp").read_text())
_CPP: Any = cppyy.gbl.cosim_ns3

REASONS: dict[int, str] = {i: str(_CPP.RadioSim.ReasonName(i)).lower() for i in range(1, 25)}
"""ns-3's ``WifiPhyRxfailureReason`` codes and their names, lower case."""


class RadioError(ValueError):
    """A call the radio refused (an index out of range, a time in the past, ...)."""


def _call(fn: Any, *args: Any) -> Any:
    """Call into C++, turning its exceptions into :class:`RadioError`."""
    try:
        return fn(*args)
    except (cppyy.gbl.std.exception, TypeError, ValueError) as e:
        raise RadioError(str(e).split("=>")[-1].strip()) from None


class Radio:
    """N nodes on one 802.11 ad-hoc network (see ``radio.cpp`` for what each key does).

    Args:
        n_nodes: how many nodes.
        standard: ``80211a``, ``80211g``, ``80211n`` (2.4 GHz, channel 1) or ``80211p``.
        rate: the WifiMode of data, control and broadcast frames (checked against the PHY's).
        tx_power_dbm: transmit power (dBm).
        exponent: log-distance path-loss exponent.
        reference_loss_db: path loss at 1 m (dB).
        nakagami: Nakagami fading after the walls.
        detection_dbm: weakest frame whose preamble is detected (dBm).
        walls: flat ``x0, y0, x1, y1, ...`` wall segments (m, ``map``).
        wall_loss_db: loss per crossed wall segment (dB).
        seed: ns-3's ``RngSeedManager`` seed.
        run: ns-3's run number.
    """

    def __init__(
        self,
        n_nodes: int,
        *,
        standard: str,
        rate: str,
        tx_power_dbm: float,
        exponent: float,
        reference_loss_db: float,
        nakagami: bool,
        detection_dbm: float,
        walls: list[float],
        wall_loss_db: float,
        seed: int,
        run: int,
    ) -> None:
        c = _CPP.RadioConfig()
        c.n_nodes = int(n_nodes)
        c.standard = standard
        c.rate = rate
        c.tx_power_dbm = float(tx_power_dbm)
        c.exponent = float(exponent)
        c.reference_loss_db = float(reference_loss_db)
        c.nakagami = bool(nakagami)
        c.preamble_min_rssi_dbm = float(detection_dbm)
        c.rx_sensitivity_dbm = min(-101.0, float(detection_dbm))
        c.walls = cppyy.gbl.std.vector["double"]([float(v) for v in walls])
        c.wall_loss_db = float(wall_loss_db)
        c.seed = int(seed)
        c.run = int(run)
        self.sim: Any = _CPP.RadioSim()
        _call(self.sim.Setup, c)

    def set_positions(self, xy: np.ndarray) -> None:
        """Every node's position now, (n, 2) (m, ``map``)."""
        a = np.ascontiguousarray(xy, dtype=np.float64)
        _call(self.sim.SetPositions, a.ctypes.data, a.shape[0], a.shape[1])

    def send_many(
        self, t_ns: np.ndarray, src: np.ndarray, ids: np.ndarray, nbytes: np.ndarray
    ) -> None:
        """Broadcast ``nbytes[k]`` from node ``src[k]`` at ``t_ns[k]`` (ns), id ``ids[k]``."""
        t = np.ascontiguousarray(t_ns, dtype=np.int64)
        s = np.ascontiguousarray(src, dtype=np.int32)
        i = np.ascontiguousarray(ids, dtype=np.int64)
        b = np.ascontiguousarray(nbytes, dtype=np.int32)
        d = np.full(len(t), -1, dtype=np.int32)
        if len(t):
            _call(
                self.sim.SendMany,
                t.ctypes.data,
                s.ctypes.data,
                i.ctypes.data,
                b.ctypes.data,
                d.ctypes.data,
                len(t),
            )

    def run_until(self, t_ns: int, *, stop_on_rx: bool = False) -> tuple[np.ndarray, np.ndarray]:
        """Run to ``t_ns`` (ns), or to the first reception; the records since the last run.

        Args:
            t_ns: where to stop (ns).
            stop_on_rx: stop right after the first message is received (:attr:`now_ns`
                says when), so that whoever gets it may answer before the radio moves on.
        """
        self.sim.SetStopOnRx(bool(stop_on_rx))
        _call(self.sim.RunUntil, int(t_ns))
        rx = np.empty(int(self.sim.NumRx()), dtype=RX_DTYPE)
        self.sim.DrainRx(rx.ctypes.data)
        drops = np.empty(int(self.sim.NumDrop()), dtype=DROP_DTYPE)
        self.sim.DrainDrop(drops.ctypes.data)
        return rx, drops

    @property
    def now_ns(self) -> int:
        """The radio's time (ns)."""
        return int(self.sim.NowNs())

    def abort_for_test(self) -> None:
        """Make ns-3 abort the process at the next run (an event in the past)."""
        self.sim.UncheckedScheduleSend(int(self.sim.NowNs()) - 1, 0)

    def close(self) -> None:
        """Destroy the simulation (a new radio may be built in this process)."""
        self.sim.Release()

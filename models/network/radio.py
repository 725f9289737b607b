"""Radio reception over distance: log-distance path loss with log-normal shadowing.

The received power at distance d (m) is, in dB (Rappaport, *Wireless Communications:
Principles and Practice*, 2nd ed., 2002, sec. 4.9.1 log-distance path loss and
sec. 4.9.2 log-normal shadowing)::

    rssi(d) = P_tx - PL(d0) - 10 n log10(d / d0) + X_sigma,   X_sigma ~ N(0, sigma^2) dB,

with reference distance d0 = 1 m. A packet is received when rssi >= the receiver's
sensitivity, so the reception probability is a Gaussian tail (Rappaport's Q-function form)::

    P(d) = Phi((mean_rssi(d) - sensitivity) / sigma).

Defaults, for indoor 5 GHz Wi-Fi:

* ``tx_power_dbm = 20``: 100 mW, a common client/AP transmit power.
* ``ref_loss_db = 46.7``: free-space loss at 1 m, ``20 log10(4 pi d0 f / c)``, at
  f = 5.18 GHz (channel 36); see :func:`free_space_loss_db`. (40 dB is the 2.4 GHz value.)
* ``exponent = 3``: between free space (2) and heavily obstructed buildings; Rappaport's
  table of exponents (Table 4.2) is commonly quoted as 2-3 for obstructed factories, the
  closest match to a warehouse, and 4-6 for obstructed office buildings.
* ``sensitivity_dbm = -82``: the minimum input sensitivity IEEE 802.11 requires for the
  lowest OFDM rate (BPSK 1/2, 6 Mb/s) in a 20 MHz channel (IEEE 802.11-2016, 17.3.10.2,
  receiver minimum input sensitivity table).
* ``shadowing_db = 4``: within the 3-6 dB shadow-fading deviations of the IEEE 802.11
  TGn indoor channel models (Erceg et al., 2004) and the low end of Rappaport's measured
  indoor values.

With these defaults the mean RSSI meets the sensitivity at about 70 m (reception 1/2).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
from scipy.special import ndtr

from models.arrays import FloatArray
from models.errors import ModelError

SPEED_OF_LIGHT_MPS = 299_792_458.0
REFERENCE_DISTANCE_M = 1.0


def free_space_loss_db(distance_m: float, frequency_hz: float) -> float:
    """Free-space (Friis) path loss between isotropic antennas: ``20 log10(4 pi d f / c)`` (dB)."""
    return 20.0 * math.log10(4.0 * math.pi * distance_m * frequency_hz / SPEED_OF_LIGHT_MPS)


@dataclass(frozen=True)
class PathLoss:
    """Log-distance path loss with log-normal shadowing (see module docstring).

    Distances below the 1 m reference distance are taken as 1 m.

    Attributes:
        tx_power_dbm: transmit power (dBm).
        ref_loss_db: path loss at 1 m (dB).
        exponent: path loss exponent n (> 0).
        sensitivity_dbm: the weakest received power that is decoded (dBm).
        shadowing_db: standard deviation of the shadowing (dB, >= 0); 0 makes reception
            a step at the distance where the mean RSSI meets the sensitivity.
        wall_loss_db: loss for every wall, shelf or obstacle between the two ends (dB,
            >= 0): the multi-wall model of COST 231 (a constant loss per wall on top of
            the distance loss), walls counted by :func:`models.network.shadowing.boxes_crossed`.
    """

    tx_power_dbm: float = 20.0
    ref_loss_db: float = 46.7
    exponent: float = 3.0
    sensitivity_dbm: float = -82.0
    shadowing_db: float = 4.0
    wall_loss_db: float = 0.0

    def __post_init__(self) -> None:
        for key, value in (
            ("network.tx_power_dbm", self.tx_power_dbm),
            ("network.ref_loss_db", self.ref_loss_db),
            ("network.sensitivity_dbm", self.sensitivity_dbm),
        ):
            if not math.isfinite(value):
                raise ModelError(key, value, "a finite number of dB")
        if not (math.isfinite(self.exponent) and self.exponent > 0.0):
            raise ModelError("network.path_loss_exponent", self.exponent, "a number > 0")
        if not (math.isfinite(self.shadowing_db) and self.shadowing_db >= 0.0):
            raise ModelError("network.shadowing_db", self.shadowing_db, "a number of dB >= 0")
        if not (math.isfinite(self.wall_loss_db) and self.wall_loss_db >= 0.0):
            raise ModelError("network.wall_loss_db", self.wall_loss_db, "a number of dB >= 0")

    @property
    def margin_db(self) -> float:
        """Link budget at the reference distance: ``tx_power - ref_loss - sensitivity`` (dB)."""
        return self.tx_power_dbm - self.ref_loss_db - self.sensitivity_dbm

    def rssi_dbm(self, d_m: npt.ArrayLike) -> FloatArray:
        """Mean received power (dBm) at distance ``d_m`` (m), without shadowing."""
        d = np.maximum(np.asarray(d_m, dtype=np.float64), REFERENCE_DISTANCE_M)
        loss_db = 10.0 * self.exponent * np.log10(d)
        return np.asarray(self.tx_power_dbm - self.ref_loss_db - loss_db, dtype=np.float64)

    def reception_probability(self, d_m: npt.ArrayLike) -> FloatArray:
        """P(rssi + shadowing >= sensitivity) at distance ``d_m`` (m), elementwise."""
        excess = self.rssi_dbm(d_m) - self.sensitivity_dbm
        if self.shadowing_db == 0.0:
            return (excess >= 0.0).astype(np.float64)
        return np.asarray(ndtr(excess / self.shadowing_db), dtype=np.float64)

    def reception_probability_at(self, d_m: float, walls: int = 0) -> float:
        """:meth:`reception_probability` for one distance and ``walls`` walls in between."""
        d = d_m if d_m > REFERENCE_DISTANCE_M else REFERENCE_DISTANCE_M
        excess = self.margin_db - 10.0 * self.exponent * math.log10(d) - self.wall_loss_db * walls
        if self.shadowing_db == 0.0:
            return 1.0 if excess >= 0.0 else 0.0
        return 0.5 * math.erfc(-excess / (self.shadowing_db * math.sqrt(2.0)))

    def median_range_m(self) -> float:
        """Distance (m) where the mean RSSI equals the sensitivity: reception probability 1/2.

        Returns 1 m when even the reference distance is below sensitivity.
        """
        return max(REFERENCE_DISTANCE_M, math.pow(10.0, self.margin_db / (10.0 * self.exponent)))

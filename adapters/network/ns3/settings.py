"""``[ns3]``: the radio of the ``ns3`` network backend (``network.backend = "ns3"``).

Every robot and the base station are nodes of one 802.11 ad-hoc network simulated by
ns-3: the robots where the kernel says they are, the base station at ``base_xy_m``.
Signals fade with distance as ns-3's ``LogDistancePropagationLossModel``
(``path_loss_exponent``, ``reference_loss_db`` at 1 m), optionally with Nakagami fading
(``fading``), and lose ``wall_loss_db`` for every wall, shelf or obstacle the straight line
between two nodes meets (:mod:`models.network.shadowing`). A frame is received when its
power is above ``detection_threshold_dbm`` and it survives the interference of the frames
on the air with it (ns-3's Yans PHY and its error model).

Defaults: 802.11g at 6 Mbit/s (data, control and broadcast frames alike), 20 dBm, path
loss exponent 3 (indoors) and the free-space loss at 1 m at 2.4 GHz as the reference
(20 log10(4 pi / lambda) = 40.05 dB, lambda = 0.125 m; ns-3's own default, 46.68 dB, is
that of 5.15 GHz), so that in the open a frame reaches -82 dBm at about 115 m; each shelf
in between takes 10 dB, a tenth of that range per shelf with exponent 3.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar, Literal

from cosim.scenario.fields import param

Standard = Literal["80211a", "80211g", "80211n", "80211p"]
Sync = Literal["window", "exact"]
Fading = Literal["none", "nakagami"]


@dataclass(frozen=True)
class Ns3Settings:
    """``[ns3]``: the 802.11 radio every host shares under ``network.backend = "ns3"``."""

    ORDER: ClassVar[int] = 51
    """In a resolved scenario file, right after ``[network]``."""

    standard: Standard = param(
        "80211g", "the 802.11 standard: '80211a', '80211g', '80211n' (2.4 GHz) or '80211p'"
    )
    rate: str = param(
        "ErpOfdmRate6Mbps",
        "ns-3's constant data and control mode, a name of its WifiMode (e.g. ErpOfdmRate6Mbps "
        "for 802.11g, OfdmRate6Mbps for a and p, HtMcs0 for n)",
    )
    tx_power_dbm: float = param(20.0, "transmit power of every node (dBm)", ge=-30, le=40)
    path_loss_exponent: float = param(
        3.0,
        "exponent of the log-distance path loss (2: free space, 3-4: indoors)",
        ge=1,
        le=6,
        unit="exponent",
    )
    reference_loss_db: float = param(
        40.05, "path loss at 1 m (dB): free space at 2.4 GHz", ge=0, le=100
    )
    fading: Fading = param(
        "none", "small-scale fading on top of the path loss: 'none' or 'nakagami' (m = 1.5, 0.75)"
    )
    detection_threshold_dbm: float = param(
        -82.0,
        "weakest frame a receiver detects (dBm): ns-3's RxSensitivity; without fading the "
        "range ends where the path loss reaches it",
        ge=-120,
        le=0,
    )
    wall_loss_db: float = param(
        10.0,
        "loss for every wall, shelf or obstacle the straight line between two nodes meets (dB)",
        ge=0,
        le=100,
    )
    sync: Sync = param(
        "window",
        "how the radio keeps time with the kernel: 'window' (lockstep windows of window_ms: "
        "a message received within its window arrives at the window's end) or 'exact' (the "
        "radio runs to the next kernel event or the next reception, whichever comes first: "
        "every message arrives when its radio received it, one exchange per instant)",
    )
    window_ms: float = param(
        10.0,
        "the radio runs in lockstep windows of this length: a message received within the "
        "window it was sent in reaches the robot at the window's end, at most this late (ms)",
        gt=0,
        le=1000,
    )
    send_jitter_ms: float = param(
        5.0,
        "each message leaves its radio up to this much after it was published, uniformly "
        "(ms): the host's own delay (operating system, middleware, its timer's phase); "
        "robots publishing in the same kernel instant otherwise transmit together and collide",
        ge=0,
        le=100,
    )
    base_xy_m: tuple[float, float] | Literal["middle"] = param(
        "middle",
        "where the base station's radio stands: [x, y] (m, map), or 'middle' of the room",
    )

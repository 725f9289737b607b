"""The ``[network]`` section: latency, loss, bandwidth, range, topology and partitions.

A profile (``network.profile``) fills the link keys with published figures; keys given in
the file or with ``--set`` override it, and the resolved scenario shows the values used.

Profiles (one-way latency, jitter, loss, bandwidth), and where their numbers come from:

* ``ideal``: no latency, no loss, unlimited bandwidth.
* ``wifi_nominal``: 3 ms +- 1 ms (normal), 1 % Bernoulli loss, 50 Mbit/s. A lab 5 GHz
  Wi-Fi as in the VirTooS experiments: ROS 2 end-to-end latencies of a few milliseconds
  (Kronauer et al., "Latency Analysis of ROS2 Multi-Node Systems", MFI 2021), and packet
  delivery ratios of 98-99 % for small robot teams on a shared indoor channel (ESP-NOW
  swarm study, J. Europ. Syst. Autom. 59(5), 2026: PDR > 98 % with 3 robots).
* ``wifi_degraded``: 20 ms +- 10 ms (lognormal), Gilbert-Elliott loss with a 5 % long-run
  rate in bursts of 3 packets on average, 10 Mbit/s. The same study with 7 robots: PDR
  92-95 %, latency up to 40 ms; losses on Wi-Fi come in bursts (fading, interference),
  hence the two-state model.
* ``wifi_stress``: 100 ms +- 50 ms (lognormal), Gilbert-Elliott loss of 25 % in bursts of
  5 packets, 2 Mbit/s. Zhivkov, Schneider and Sklar ("Measuring the Effects of
  Communication Quality on Multi-robot Team Performance", TAROS 2017) sweep loss from 0 to
  75 % and see team performance fall non-linearly; Abu-Aisheh et al. (NANOCOM 2021) find
  that halving the delivery ratio triples mapping time. 25 % is well inside the range
  where such effects show.

Gilbert-Elliott parameters follow netem's ``loss gemodel p r 1-h 1-k``: with 1-h = 1 and
1-k = 0, the long-run loss is p / (p + r) and the mean burst length 1 / r, so a 5 % rate in
bursts of 3 is r = 1/3, p = 0.0175; 25 % in bursts of 5 is r = 0.2, p = 0.0667.
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from dataclasses import dataclass
from typing import Any, ClassVar, Literal

from cosim.scenario.choices import choice_problems
from cosim.scenario.fields import Problem, param

Profile = Literal["ideal", "wifi_nominal", "wifi_degraded", "wifi_stress"]

_LINK_DEFAULTS: dict[str, Any] = {
    "latency_model": "constant",
    "latency_ms": 0.0,
    "jitter_ms": 0.0,
    "loss_model": "none",
    "loss_prob": 0.0,
    "ge_p": 0.0,
    "ge_r": 1.0,
    "ge_loss_bad": 1.0,
    "ge_loss_good": 0.0,
    "bandwidth_mbps": 0.0,
}

PROFILES: dict[str, dict[str, Any]] = {
    "ideal": dict(_LINK_DEFAULTS),
    "wifi_nominal": {
        **_LINK_DEFAULTS,
        "latency_model": "normal",
        "latency_ms": 3.0,
        "jitter_ms": 1.0,
        "loss_model": "bernoulli",
        "loss_prob": 0.01,
        "bandwidth_mbps": 50.0,
    },
    "wifi_degraded": {
        **_LINK_DEFAULTS,
        "latency_model": "lognormal",
        "latency_ms": 20.0,
        "jitter_ms": 10.0,
        "loss_model": "gilbert_elliott",
        "ge_p": round(0.05 * (1 / 3) / 0.95, 6),
        "ge_r": round(1 / 3, 6),
        "bandwidth_mbps": 10.0,
    },
    "wifi_stress": {
        **_LINK_DEFAULTS,
        "latency_model": "lognormal",
        "latency_ms": 100.0,
        "jitter_ms": 50.0,
        "loss_model": "gilbert_elliott",
        "ge_p": round(0.25 * 0.2 / 0.75, 6),
        "ge_r": 0.2,
        "bandwidth_mbps": 2.0,
    },
}


@dataclass(frozen=True)
class PartitionConfig:
    """``[[network.partitions]]``: a scheduled outage.

    Either ``hosts`` (that group is cut off from every other host) or ``links`` (these
    undirected links are down), during ``[from_s, to_s)``.
    """

    from_s: float = param(0.0, "start of the outage (s)", ge=0)
    to_s: float = param(0.0, "end of the outage (s), exclusive", ge=0)
    hosts: tuple[str, ...] = param((), "hosts cut off from all others")
    links: tuple[tuple[str, str], ...] = param((), "undirected links [[a, b], ...] cut")

    def problems(self) -> Iterator[Problem]:
        """A window must not be empty and must name hosts or links (not both)."""
        if self.to_s <= self.from_s:
            yield Problem("to_s", self.to_s, f"a time after from_s ({self.from_s:g} s)")
        if bool(self.hosts) == bool(self.links):
            yield Problem("hosts", list(self.hosts), "either hosts or links (exactly one)")


@dataclass(frozen=True)
class NetworkConfig:
    """``[network]``: the links between hosts (robots and the base station)."""

    ORDER: ClassVar[int] = 50
    """Where the section comes in a resolved scenario and in the adapters' order."""

    PROFILES: ClassVar[Mapping[str, Mapping[str, Any]]] = PROFILES

    profile: Profile = param("ideal", "preset of the link keys; explicit keys override it")
    backend: str = param(
        "links",
        "what decides if and when a message between hosts arrives: a registered network "
        "backend (links: every link by itself, with the keys below)",
        registry="cosim.network_backends",
    )
    topology: str = param(
        "complete",
        "which robots can talk directly: a registered topology (complete, range, binomial, "
        "ring, explicit)",
        registry="cosim.topologies",
    )
    edge_prob: float = param(0.5, "binomial topology: probability of each edge", gt=0, le=1)
    edges: tuple[tuple[str, str], ...] = param((), "explicit topology: [[a, b], ...]")
    latency_model: str = param(
        "constant",
        "one-way latency distribution: a registered latency model (constant, normal, "
        "lognormal, empirical)",
        registry="cosim.latency_models",
    )
    latency_ms: float = param(0.0, "mean one-way latency (ms)", ge=0)
    jitter_ms: float = param(0.0, "latency standard deviation (ms)", ge=0)
    latency_csv: str = param("", "empirical model: CSV of measured one-way delays (ms)", path=True)
    reorder: bool = param(False, "let a later message overtake an earlier one on a link")
    loss_model: str = param(
        "none",
        "packet loss process of every directed link: a registered loss model (none, "
        "bernoulli, gilbert_elliott)",
        registry="cosim.loss_models",
    )
    loss_prob: float = param(0.0, "bernoulli: loss probability per message", ge=0, le=1)
    ge_p: float = param(
        0.0, "gilbert_elliott: P(good -> bad) per message (netem p)", ge=0, le=1, unit="probability"
    )
    ge_r: float = param(
        1.0, "gilbert_elliott: P(bad -> good) per message (netem r)", ge=0, le=1, unit="probability"
    )
    ge_loss_bad: float = param(
        1.0, "gilbert_elliott: loss probability in bad (netem 1-h)", ge=0, le=1, unit="probability"
    )
    ge_loss_good: float = param(
        0.0, "gilbert_elliott: loss probability in good (netem 1-k)", ge=0, le=1, unit="probability"
    )
    bandwidth_mbps: float = param(0.0, "sending rate of every host (Mbit/s), 0 = unlimited", ge=0)
    queue_packets: int = param(
        100, "messages that may wait at a sending interface", ge=1, le=1_000_000, unit="count"
    )
    range_m: float = param(0.0, "robot-to-robot range cut-off (m), 0 = unlimited", ge=0)
    path_loss: bool = param(False, "log-distance path loss with shadowing between robots")
    path_loss_exponent: float = param(
        3.0, "path loss exponent (indoor obstructed ~3)", gt=0, unit="exponent"
    )
    tx_power_dbm: float = param(20.0, "transmit power (dBm)")
    ref_loss_db: float = param(
        46.7, "path loss at 1 m (dB): free space at 5.18 GHz, Wi-Fi channel 36", ge=0
    )
    sensitivity_dbm: float = param(-82.0, "receiver sensitivity (dBm)")
    shadowing_db: float = param(4.0, "log-normal shadowing deviation (dB)", ge=0)
    airtime_mbps: float = param(
        0.0,
        "the rate of one radio channel every host shares (Mbit/s): each message takes its "
        "turn on it with its headers and the 802.11g frame overheads, so latency grows with "
        "how many robots send how many bytes; 0: none (each host's bandwidth_mbps instead)",
        ge=0,
        le=10_000,
    )
    wall_loss_db: float = param(
        0.0,
        "path loss: loss for every wall, shelf or obstacle the straight line between two "
        "robots meets (dB; COST 231's multi-wall model); 0: line of sight ignored",
        ge=0,
        le=100,
    )
    topology_update_hz: float = param(10.0, "rate of link up/down updates (Hz)", gt=0, le=1000)
    partitions: tuple[PartitionConfig, ...] = param((), "scheduled outages")

    def problems(self) -> Iterator[Problem]:
        """What the chosen models cannot run with, and keys only unchosen ones read."""
        for key in ("backend", "latency_model", "loss_model", "topology"):
            yield from choice_problems(self, key)
        if self.airtime_mbps > 0 and self.bandwidth_mbps > 0:
            yield Problem(
                "bandwidth_mbps",
                self.bandwidth_mbps,
                "0 with airtime_mbps set (the shared channel serializes every host's messages)",
            )
        if self.wall_loss_db > 0 and not self.path_loss:
            yield Problem("wall_loss_db", self.wall_loss_db, "0 unless path_loss = true")

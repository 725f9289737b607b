"""``network.backend = "ns3"``: every message crosses an 802.11 network simulated by ns-3.

Every robot and the base station are nodes of one ad-hoc Wi-Fi network (``[ns3]``:
standard, rate, power, path loss, fading, detection threshold, a loss per wall, shelf or
obstacle in between). A message a radio node publishes to other hosts is one UDP broadcast
of its real size (fragmented by ns-3 when larger than a frame), on the air at its exact time
plus the send jitter of its host (``ns3.send_jitter_ms``, seeded); each destination gets it
if its node received every fragment, at the time it did. What each host's radio measured
of each sender's last message is offered to protocols
(:class:`~adapters.network.contract.RadioView`).

The radio runs in a process of its own (:mod:`adapters.network.ns3.process`). With
``ns3.sync = "window"`` it keeps lockstep with the kernel: every ``ns3.window_ms`` the
backend hands it the robots' positions and the messages sent in the window, lets it run to
the window's end, and tells the bus what arrived (:meth:`cosim.core.bus.Bus.settle`); a
copy that arrived within the window it was sent in reaches its host at the window's end,
at most a window late. With ``"exact"``, last in every instant with something on the air
(stage ``LINK``) it runs the radio to the kernel's next event or to its first reception,
whichever comes first, so every copy arrives when its radio received it and an answer
goes on the air at its own time. ``tables/radio`` keeps the radio's own times, the
received signal and SNR, and why a copy was lost (ns-3's reason for a frame it heard and
dropped, ``unheard`` for a frame below its detection threshold, ``run_ended`` for what was
still on the air at the end).

Hosts that are not radio nodes (motion capture, external bridges) are wired: what they
send arrives at once. The radio is seeded from the run's seed (identical tables on
re-run); its process is kept for the next run of the same process (a study's worker starts
one), and exits with it; if ns-3 aborts it, the run ends with one line naming ns-3's reason
and keeps what it recorded.
"""

from __future__ import annotations

import importlib.util
import time
from collections.abc import Iterator, Mapping, Sequence
from typing import Any, ClassVar

import numpy as np

from adapters.network.contract import NetworkContext, RadioView
from adapters.network.ns3.process import RadioProcess, RadioRefusedError, acquire, release
from adapters.network.ns3.settings import Ns3Settings
from adapters.network.ns3.wire import DROP_DTYPE, RX_DTYPE
from adapters.network.settings import NetworkConfig
from cosim.core.adapter import RunContext
from cosim.core.errors import ConfigError
from cosim.core.hosts import BASE_HOST, HostId
from cosim.core.kernel import Stage
from cosim.core.link import DELIVERED, AllDelivered, Later, Transfer
from cosim.core.summary import SummaryKey
from cosim.core.table import TableSpec
from cosim.core.timebase import NS_PER_S
from cosim.scenario.fields import Problem
from models.fleet.kinematics import FleetState
from models.network.radio import PathLoss
from models.network.shadowing import boxes_crossed
from models.network.topology import Edges, edge
from models.world.warehouse import Warehouse

RADIO = TableSpec(
    "radio",
    "Every copy of a message the ns-3 radio carried: when it arrived on the radio, how "
    "strong, or why not.",
    {
        "t_sent_s": "when it was sent (s)",
        "t_radio_s": "when the destination's radio received its last fragment (s); NaN: lost",
        "src": "sending host",
        "dst": "destination host",
        "topic": "topic",
        "nbytes": "message size (bytes)",
        "status": "delivered, or why not: ns-3's reason, unheard (below the detection "
        "threshold) or run_ended",
        "rssi_dbm": "received signal of its last frame (dBm); NaN: not received",
        "snr_db": "its signal over noise and interference (dB); NaN: not received",
    },
    categorical=("src", "dst", "topic", "status"),
)
RADIO_COLUMNS = tuple(RADIO.columns)

GIVE_UP_NS = 500_000_000
"""A copy not received this long after it was sent is lost (ns): ns-3's MAC drops a frame
queued longer (its ``WifiMacQueue`` MaxDelay, 500 ms)."""


def _installed() -> bool:
    return (
        importlib.util.find_spec("ns") is not None and importlib.util.find_spec("cppyy") is not None
    )


class Ns3Backend:
    """Every robot and the base station on one 802.11 network simulated by ns-3."""

    name: ClassVar[str] = "ns3"
    tables: ClassVar[tuple[TableSpec, ...]] = (RADIO,)
    summary_keys: ClassVar[Mapping[str, SummaryKey]] = {
        "radio_copies": SummaryKey("count", "copies of messages the radio carried"),
        "radio_delivered": SummaryKey("count", "copies the radio delivered"),
        "radio_wall_s": SummaryKey(
            "s", "wall time the radio's process spent simulating", volatile=True
        ),
        "radio_start_s": SummaryKey(
            "s", "wall time to start the radio's process and build the network", volatile=True
        ),
    }
    """The summary keys :meth:`finish` writes."""

    @classmethod
    def problems(cls, network: NetworkConfig) -> Iterator[Problem]:
        """Without ns-3's Python package the backend cannot run: say how to install it."""
        if not _installed():
            yield Problem(
                "backend",
                "ns3",
                "ns-3's Python package, not installed here: pip install 'cosim[ns3]' (builds "
                "cppyy, about 2 min and 600 MB)",
            )

    def __init__(self, context: NetworkContext) -> None:
        run = context.run
        self.cfg = run.settings(Ns3Settings)
        self.fleet = run.service(FleetState)
        self.robots = list(context.robots)
        self.node = {HostId(r): i for i, r in enumerate(self.robots)}
        self.node[BASE_HOST] = len(self.robots)
        world = run.service(Warehouse)
        self.base_xy = (
            np.array([world.size_m[0] / 2, world.size_m[1] / 2])
            if self.cfg.base_xy_m == "middle"
            else np.array(self.cfg.base_xy_m, dtype=float)
        )
        self.boxes = np.asarray(world.inner_boxes, dtype=float).reshape(-1, 4)
        self.seed = run.scenario.seed
        self.source = run.scenario.source
        self.mean_power = PathLoss(
            tx_power_dbm=self.cfg.tx_power_dbm,
            ref_loss_db=self.cfg.reference_loss_db,
            exponent=self.cfg.path_loss_exponent,
            sensitivity_dbm=self.cfg.detection_threshold_dbm,
            shadowing_db=0.0,
        )
        """The radio's mean received power without fading (who hears whom, :meth:`links_at`)."""
        self.window_ns = max(round(self.cfg.window_ms * 1e6), 1)
        self.jitter_ns = round(self.cfg.send_jitter_ms * 1e6)
        self.rng = run.rng.stream("ns3/jitter")
        self.table = run.recorder.table(RADIO)
        self.view = RadioView()
        run.provide(self.view)
        self.bus: Any = None
        self.process: RadioProcess | None = None
        self.next_ticket = 0
        self.sends: list[tuple[int, int, int, int]] = []
        """Queued for the radio: (t_ns, node, ticket, nbytes)."""
        self.flying: dict[int, tuple[int, HostId, tuple[HostId, ...], str, int]] = {}
        """Not settled yet, by ticket: (t_sent_ns, src, destinations, topic, nbytes)."""
        self.got: dict[int, dict[HostId, tuple[int, float, float]]] = {}
        """Receptions so far, by ticket and destination: (t_ns, rssi_dbm, snr_db)."""
        self.dropped: dict[tuple[int, int], str] = {}
        self.reasons: dict[int, str] = {}
        self.wall_s = 0.0
        self.start_s = 0.0
        self.copies = 0
        self.delivered = 0

    # -- the radio's process ---------------------------------------------------------
    def start(self, run: RunContext) -> None:
        """Start the radio's process, build the network, and step it every window."""
        started = time.perf_counter()
        self.bus = run.bus
        self.process = acquire()
        try:
            self.process.call("setup", self._radio_config())
        except RadioRefusedError as refused:  # the only key the radio alone can check
            known = str(refused).rsplit("known:", 1)[-1].split()
            raise ConfigError(
                f"{self.source}: [ns3] rate = {self.cfg.rate!r}: not a mode of "
                f"{self.cfg.standard}; expected one of {', '.join(known)}"
            ) from None
        self.reasons = dict(self.process.call("reasons"))
        self.start_s = time.perf_counter() - started
        self.kernel = run.kernel
        self.exact = self.cfg.sync == "exact"
        self.stepping = False
        if not self.exact:
            run.kernel.every(
                self.window_ns, self._window, stage=Stage.PHYSICS, start_ns=self.window_ns
            )

    def _radio_config(self) -> dict[str, Any]:
        """What the radio's ``setup`` is built from (the ``[ns3]`` keys, the walls, the seed)."""
        return {
            "n_nodes": len(self.node),
            "standard": self.cfg.standard,
            "rate": self.cfg.rate,
            "tx_power_dbm": self.cfg.tx_power_dbm,
            "exponent": self.cfg.path_loss_exponent,
            "reference_loss_db": self.cfg.reference_loss_db,
            "nakagami": self.cfg.fading == "nakagami",
            "detection_dbm": self.cfg.detection_threshold_dbm,
            "walls": self.boxes.ravel().tolist(),
            "wall_loss_db": self.cfg.wall_loss_db,
            "seed": 1 + self.seed % (2**31 - 2),
            "run": 1,
        }

    def positions(self) -> np.ndarray:
        """Every node's position now (m, ``map``): the robots', then the base station's."""
        xy = np.empty((len(self.node), 2))
        xy[: len(self.robots), 0] = self.fleet.x
        xy[: len(self.robots), 1] = self.fleet.y
        xy[-1] = self.base_xy
        return xy

    # -- messages ----------------------------------------------------------------------
    def transmit(
        self, t_ns: int, src: HostId, dsts: Sequence[HostId], nbytes: int, topic: str
    ) -> Sequence[Transfer] | AllDelivered | Later:
        """A radio node's message goes on the air (told later); a wired host's arrives now."""
        node = self.node.get(src)
        if node is None:
            return AllDelivered(t_ns)
        ticket = self.next_ticket
        self.next_ticket += 1
        jitter = int(self.rng.integers(self.jitter_ns)) if self.jitter_ns > 0 else 0
        self.sends.append((t_ns + jitter, node, ticket, max(int(nbytes), 8)))
        self.flying[ticket] = (t_ns, src, tuple(dsts), topic, int(nbytes))
        self.got[ticket] = {}
        if self.exact and not self.stepping:
            self.stepping = True
            self.kernel.at(t_ns, lambda: self._catch_up(t_ns), Stage.LINK)
        return Later(ticket)

    def _window(self, now_ns: int) -> None:
        """Window mode: the radio runs to the window's end."""
        self._step(now_ns)

    def _catch_up(self, now_ns: int) -> None:
        """Exact mode: run the radio to the kernel's next event or its first reception.

        Runs last in an instant (stage ``LINK``), after every message of the instant was
        handed over; what the radio received is delivered when it received it, and this
        runs again then, so that an answer to it goes on the air at its own time. Once
        nothing is on the air it rests until the next message.
        """
        nxt = self.kernel.env.peek()  # the kernel's next event, this one already taken
        until = now_ns + GIVE_UP_NS
        if nxt != float("inf"):
            until = max(min(int(nxt), until), now_ns)
        then = max(self._step(until, stop_on_rx=True), now_ns)
        if self.flying or self.sends:
            self.kernel.at(then, lambda: self._catch_up(then), Stage.LINK)
        else:
            self.stepping = False

    def _step(self, now_ns: int, *, stop_on_rx: bool = False) -> int:
        """Run the radio to ``now_ns`` (or its first reception) and settle what it can tell.

        Returns:
            The radio's time after the run (ns).
        """
        assert self.process is not None
        sends = None
        if self.sends:
            t, node, ticket, nbytes = (np.array(c) for c in zip(*self.sends, strict=True))
            sends = (t, node, ticket, nbytes)
            self.sends = []
        rx_bytes, drop_bytes, took, radio_now = self.process.call(
            "step",
            {
                "positions": self.positions(),
                "sends": sends,
                "until": now_ns,
                "stop_on_rx": stop_on_rx,
            },
        )
        self.wall_s += took
        self._note(np.frombuffer(rx_bytes, RX_DTYPE), np.frombuffer(drop_bytes, DROP_DTYPE))
        self._settle(int(radio_now), final=False)
        return int(radio_now)

    def _note(self, rx: np.ndarray, drops: np.ndarray) -> None:
        hosts = list(self.node)
        for r in rx.tolist():
            t_ns, ticket, node, _src, rssi, snr = r
            got = self.got.get(int(ticket))
            if got is not None:
                got[hosts[node]] = (int(t_ns), float(rssi), float(snr))
        for d in drops.tolist():
            _t, ticket, node, _src, reason, _frag = d
            if ticket >= 0:
                self.dropped[(int(ticket), int(node))] = self.reasons.get(int(reason), str(reason))

    def _settle(self, now_ns: int, *, final: bool) -> None:
        """Tell the bus the fate of every transmission whose every copy is known."""
        for ticket in list(self.flying):
            t_sent, src, dsts, topic, nbytes = self.flying[ticket]
            got = self.got[ticket]
            late = final or now_ns - t_sent >= GIVE_UP_NS
            if not late and any(d in self.node and d not in got for d in dsts):
                continue
            transfers, rows = [], []
            for dst in dsts:
                if dst in got:
                    t_rx, rssi, snr = got[dst]
                    self.view.heard(dst, src, max(t_rx, now_ns), rssi, snr)
                    transfers.append(Transfer(dst, DELIVERED, t_rx))
                    rows.append((dst, t_rx / NS_PER_S, DELIVERED, rssi, snr))
                elif dst not in self.node:  # a wired host hears the base station at once
                    transfers.append(Transfer(dst, DELIVERED, t_sent))
                    rows.append((dst, t_sent / NS_PER_S, DELIVERED, np.nan, np.nan))
                else:
                    why = (
                        "run_ended"
                        if final and now_ns - t_sent < GIVE_UP_NS
                        else (self.dropped.get((ticket, self.node[dst]), "unheard"))
                    )
                    transfers.append(Transfer(dst, why, None))
                    rows.append((dst, np.nan, why, np.nan, np.nan))
            del self.flying[ticket], self.got[ticket]
            self.copies += len(rows)
            self.delivered += sum(1 for r in rows if r[2] == DELIVERED)
            self.table.extend(
                t_sent_s=[t_sent / NS_PER_S] * len(rows),
                t_radio_s=[r[1] for r in rows],
                src=[src] * len(rows),
                dst=[r[0] for r in rows],
                topic=[topic] * len(rows),
                nbytes=[nbytes] * len(rows),
                status=[r[2] for r in rows],
                rssi_dbm=[r[3] for r in rows],
                snr_db=[r[4] for r in rows],
            )
            self.bus.settle(ticket, transfers)
        self.dropped = {k: v for k, v in self.dropped.items() if k[0] in self.flying}

    # -- who hears whom ------------------------------------------------------------------
    def links_at(self, t_ns: int) -> Edges:
        """Pairs of radio nodes whose mean signal (no fading) is above the detection threshold."""
        xy = self.positions()
        hosts = list(self.node)
        i, j = np.triu_indices(len(hosts), 1)
        d = np.hypot(*(xy[i] - xy[j]).T)  # the path loss takes under 1 m as 1 m
        walls = boxes_crossed(xy[i], xy[j], self.boxes)
        power = self.mean_power.rssi_dbm(d) - self.cfg.wall_loss_db * walls
        up = power >= self.cfg.detection_threshold_dbm
        return frozenset(edge(hosts[a], hosts[b]) for a, b in zip(i[up], j[up], strict=True))

    def robot_graph(self) -> tuple[list[str], Edges]:
        """Every robot may talk to every other (the radio decides who hears)."""
        r = self.robots
        return list(r), frozenset(edge(a, b) for k, a in enumerate(r) for b in r[k + 1 :])

    def finish(self, run: RunContext) -> Mapping[str, Any]:
        """Settle what is left (still on the air: ``run_ended``), and say what it carried."""
        self._settle(run.kernel.now_ns, final=True)
        self.close()
        return {
            "radio_copies": self.copies,
            "radio_delivered": self.delivered,
            "radio_wall_s": round(self.wall_s, 3),
            "radio_start_s": round(self.start_s, 3),
        }

    def close(self) -> None:
        """Hand the radio's process back for the next run of this process (again: nothing)."""
        if self.process is not None:
            release(self.process)
            self.process = None

"""The network adapter in a running kernel: exact arrival times, drops and link records."""

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np
import pytest

import cosim
from adapters.naming import topic
from adapters.network.links import ModelLink
from cosim.core.adapter import RunContext
from cosim.core.errors import ConfigError
from cosim.core.hosts import BASE_HOST, HostId
from cosim.core.kernel import Stage
from cosim.core.link import AllDelivered, Transfer
from cosim.core.messages import Message
from cosim.core.registry import AdapterRegistry
from cosim.core.rng import RngStreams
from cosim.runner.execute import execute
from models.fleet.kinematics import FleetState
from models.network import ConstantLatency, LinkParams, NetworkModel, NoLoss
from models.network.delivery import DeliveryStatus
from models.network.topology import complete


@dataclass(frozen=True, slots=True)
class Blob(Message):
    """A test message of a given wire size."""

    ros_type: ClassVar[str] = "std_msgs/msg/ByteMultiArray"
    nbytes: int

    def size_bytes(self) -> int:
        return self.nbytes


class Pinger:
    """Test traffic: robot_1 sends a Blob to the base every 10 ms; robot_2 to robot_1."""

    name: ClassVar[str] = "pinger"
    requires: ClassVar[tuple[str, ...]] = ("network",)
    nbytes: ClassVar[int] = 100
    period_ns: ClassVar[int] = 10_000_000
    received: ClassVar[list[tuple[str, int, int]]] = []

    def __init__(self, run: RunContext) -> None:
        Pinger.received = []

    def start(self, run: RunContext) -> None:
        def keep(message: Message, envelope: Any) -> None:
            Pinger.received.append((envelope.topic, envelope.t_sent_ns, envelope.t_recv_ns))

        run.bus.subscribe("/up", BASE_HOST, keep)
        run.bus.subscribe(topic("robot_1", "peer"), HostId("robot_1"), keep)

        def send(now: int) -> None:
            run.bus.publish("/up", Blob(Pinger.nbytes), HostId("robot_1"))
            run.bus.publish(topic("robot_1", "peer"), Blob(Pinger.nbytes), HostId("robot_2"))

        run.kernel.every(Pinger.period_ns, send, stage=Stage.CONTROL)

    def finish(self, run: RunContext) -> Mapping[str, Any]:
        return {}


class Runaway:
    """Test motion: robot_2 drives away from robot_1 at 1 m/s along +x."""

    name: ClassVar[str] = "runaway"
    requires: ClassVar[tuple[str, ...]] = ("fleet",)

    def __init__(self, run: RunContext) -> None:
        self.fleet = run.service(FleetState)

    def start(self, run: RunContext) -> None:
        def push(now: int) -> None:
            self.fleet.v_cmd[1] = 1.0

        run.kernel.every(50_000_000, push, stage=Stage.CONTROL)

    def finish(self, run: RunContext) -> Mapping[str, Any]:
        return {}


REGISTRY = AdapterRegistry.from_entry_points().with_adapter(Pinger).with_adapter(Runaway)
BASE = {
    "scenario.duration_s": 1.0,
    "world.size_m": [20.0, 10.0],
    "world.shelf_count": 0,
    "robots.count": 3,
    "robots.placement": "explicit",
    "robots.positions": [[2.0, 5.0, 0.0], [3.0, 5.0, 0.0], [2.0, 8.0, 0.0]],
    "lidar.beams": 0,
}


def _run(extra: dict[str, Any], names: tuple[str, ...] = ("pinger",)):
    scenario = cosim.load_scenario("warehouse-random", {**BASE, **extra})
    return execute(scenario, names=["world", "fleet", "network", *names], registry=REGISTRY)


def test_a_constant_5_ms_latency_delivers_exactly_5_000_000_ns_after_sending():
    result = _run({"network.latency_ms": 5.0})
    up = [(s, r) for t, s, r in Pinger.received if t == "/up"]
    assert len(up) == 100
    assert all(r - s == 5_000_000 for s, r in up)
    assert [s for s, _ in up] == [k * 10_000_000 for k in range(100)]
    assert result.summary["latency_ms_p50"] == result.summary["latency_ms_p99"] == 5.0


def test_1_mbit_per_s_and_1250_byte_messages_arrive_exactly_10_ms_apart():
    Pinger.nbytes = 1250
    Pinger.period_ns = 1_000_000  # offered much faster than the link drains
    try:
        result = _run(
            {
                "network.bandwidth_mbps": 1.0,
                "scenario.duration_s": 0.2,
                "network.queue_packets": 1000,
            }
        )
    finally:
        Pinger.nbytes, Pinger.period_ns = 100, 10_000_000
    up = [r for t, _, r in Pinger.received if t == "/up"]
    assert up[:5] == [10_000_000, 20_000_000, 30_000_000, 40_000_000, 50_000_000]
    assert np.all(np.diff(up) == 10_000_000)
    assert result.summary["messages_dropped"] == 0


def test_a_full_interface_queue_drops_as_queue_full():
    Pinger.nbytes = 1250
    Pinger.period_ns = 1_000_000
    try:
        result = _run(
            {"network.bandwidth_mbps": 1.0, "scenario.duration_s": 0.1, "network.queue_packets": 5}
        )
    finally:
        Pinger.nbytes, Pinger.period_ns = 100, 10_000_000
    messages = result.tables["messages"]
    up = messages[messages["topic"] == "/up"]
    assert (up["status"] == "queue_full").sum() > 0
    assert (up["status"] == "delivered").sum() + (up["status"] == "queue_full").sum() == len(up)


@pytest.mark.parametrize(("prob", "delivered"), [(1.0, 0), (0.0, 100)])
def test_bernoulli_loss_1_drops_all_and_0_drops_none(prob, delivered):
    result = _run({"network.loss_model": "bernoulli", "network.loss_prob": prob})
    messages = result.tables["messages"]
    up = messages[messages["topic"] == "/up"]
    assert (up["status"] == "delivered").sum() == delivered
    assert (up["status"] == "lost").sum() == 100 - delivered


def test_a_partition_drops_exactly_the_messages_sent_inside_its_window():
    partition = [{"from_s": 0.25, "to_s": 0.5, "hosts": ["robot_1"]}]
    result = _run({"network.partitions": partition})
    messages = result.tables["messages"]
    for name in ("/up", "/robot_1/peer"):
        rows = messages[messages["topic"] == name]
        inside = (rows["t_sent_ns"] >= 250_000_000) & (rows["t_sent_ns"] < 500_000_000)
        assert set(rows.loc[inside, "status"]) == {"partitioned"}
        assert set(rows.loc[~inside, "status"]) == {"delivered"}
        assert inside.sum() == 25
    links = result.tables["links"]
    cut = links[~links["up"]]
    assert set(cut["t_s"]) == {0.25}
    assert {tuple(sorted(p)) for p in zip(cut["a"], cut["b"], strict=True)} == {
        ("base", "robot_1"),
        ("robot_1", "robot_2"),
        ("robot_1", "robot_3"),
    }
    back = links[(links["t_s"] == 0.5) & links["up"]]
    assert len(back) == 3


def test_the_range_cut_off_follows_robot_motion():
    result = _run({"network.range_m": 1.5, "scenario.duration_s": 1.5}, names=("pinger", "runaway"))
    messages = result.tables["messages"]
    peer = messages[messages["topic"] == "/robot_1/peer"].reset_index(drop=True)
    # robot_2 starts 1 m from robot_1 and drives away: once out of range, never back
    statuses = list(peer["status"])
    first_out = statuses.index("out_of_range")
    assert set(statuses[:first_out]) == {"delivered"}
    assert set(statuses[first_out:]) == {"out_of_range"}
    assert 0.3 < peer["t_sent_s"][first_out] < 1.0
    up = messages[messages["topic"] == "/up"]
    assert set(up["status"]) == {"delivered"}  # the base has no position: no range
    links = result.tables["links"]
    down = links[~links["up"]]
    assert [tuple(sorted(p)) for p in zip(down["a"], down["b"], strict=True)] == [
        ("robot_1", "robot_2")
    ]


def test_a_partition_naming_an_unknown_host_is_refused_with_the_key():
    with pytest.raises(ConfigError, match=r"\[network.partitions\[0\]\] names host 'robot_9'"):
        _run({"network.partitions": [{"from_s": 0.1, "to_s": 0.2, "hosts": ["robot_9"]}]})


def test_a_ring_topology_keeps_non_neighbours_apart():
    result = _run(
        {
            "network.topology": "ring",
            "robots.count": 4,
            "robots.positions": [
                [2.0, 5.0, 0.0],
                [3.0, 5.0, 0.0],
                [2.0, 8.0, 0.0],
                [5.0, 5.0, 0.0],
            ],
        }
    )
    links = result.tables["links"]
    pairs = {tuple(sorted(p)) for p in zip(links["a"], links["b"], strict=True)}
    robot_pairs = {p for p in pairs if "base" not in p}
    assert robot_pairs == {
        ("robot_1", "robot_2"),
        ("robot_2", "robot_3"),
        ("robot_3", "robot_4"),
        ("robot_1", "robot_4"),
    }


def test_the_same_seed_gives_the_same_fates_under_loss_and_jitter():
    extra = {"network.profile": "wifi_stress"}
    first = _run(extra)
    second = _run(extra)
    assert first.tables["messages"].equals(second.tables["messages"])
    assert (first.tables["messages"]["status"] == "lost").sum() > 0


def test_the_link_over_an_ideal_network_stands_for_the_transfers_of_its_links():
    """Every copy at once (AllDelivered) on an ideal network: the transfers and latencies of
    the same network forced through its links."""
    hosts = [HostId(f"h{i}") for i in range(4)]

    def link(forced: bool) -> ModelLink:
        model = NetworkModel(
            LinkParams(latency=ConstantLatency(3.0), loss_factory=NoLoss),
            streams=RngStreams(1).stream,
            bandwidth_bps=None,
            queue_packets=100,
        )
        if forced:
            model.set_edges(frozenset(complete(hosts)))
        return ModelLink(model, lambda a, b: None)

    fast, forced = link(False), link(True)
    for k in range(40):
        src = hosts[k % 4]
        dsts = [h for h in hosts if h != src][: 1 + k % 3]
        outcome = fast.transmit(k * 1_000, src, dsts, 100, "/t")
        assert isinstance(outcome, AllDelivered)
        each = [Transfer(d, DeliveryStatus.DELIVERED, outcome.t_recv_ns) for d in dsts]
        assert each == forced.transmit(k * 1_000, src, dsts, 100, "/t")
    assert list(fast.latencies_ns) == list(forced.latencies_ns) == [3_000_000] * 79


def test_walls_between_two_robots_cost_reception_with_the_wall_loss_set():
    # two robots 20 m apart with two walls between them: 20 dBm - 46.7 - 39 dB leaves a
    # 16 dB margin over -82 dBm; two 10 dB walls put it 4 dB under
    import cosim
    from cosim.runner.assembly import assemble

    base = {
        "world.size_m": [40.0, 10.0],
        "world.shelf_count": 0,
        "world.obstacles": [[14.0, 0.0, 15.0, 7.0], [20.0, 0.0, 21.0, 7.0]],
        "robots.count": 2,
        "robots.placement": "explicit",
        "robots.positions": [[5.0, 3.0, 0.0], [25.0, 3.0, 0.0]],
        "network.path_loss": True,
        "network.shadowing_db": 0.0,
    }
    for loss, heard in ((0.0, True), (10.0, False)):
        run = assemble(
            cosim.load_scenario("warehouse-random", {**base, "network.wall_loss_db": loss}),
            names=["network"],
        ).run
        backend = run.bus.link
        outcome = backend.transmit(0, "robot_1", ["robot_2"], 100, "/x")
        assert (outcome[0].status == "delivered") is heard, (loss, outcome)


def test_a_wall_loss_without_the_path_loss_is_refused():
    import pytest

    import cosim
    from cosim.core.errors import ConfigError

    with pytest.raises(ConfigError, match="wall_loss_db"):
        cosim.load_scenario("warehouse-random", {"network.wall_loss_db": 10.0})


def test_a_shared_channel_with_a_per_host_bandwidth_is_refused():
    import pytest

    import cosim
    from cosim.core.errors import ConfigError

    with pytest.raises(ConfigError, match=r"bandwidth_mbps.*airtime_mbps"):
        cosim.load_scenario(
            "warehouse-random", {"network.airtime_mbps": 6.0, "network.bandwidth_mbps": 50.0}
        )

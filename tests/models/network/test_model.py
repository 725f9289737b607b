import numpy as np
import pytest

from models.errors import ModelError
from models.network import (
    BernoulliLoss,
    ConstantLatency,
    DeliveryStatus,
    GilbertElliottLoss,
    LinkParams,
    NetworkModel,
    NoLoss,
    NormalLatency,
    Partition,
    PathLoss,
)
from models.network.topology import complete, ring

MS = 1_000_000


def no_distance(a, b):
    return None


def network(streams, *, latency=None, loss=NoLoss, bandwidth_bps=None, queue=100, **kwargs):
    link_keys = {"reorder", "path_loss", "range_m"}
    link = {k: v for k, v in kwargs.items() if k in link_keys}
    params = LinkParams(latency=latency or ConstantLatency(0.0), loss_factory=loss, **link)
    rest = {k: v for k, v in kwargs.items() if k not in link_keys}
    return NetworkModel(
        params, streams=streams, bandwidth_bps=bandwidth_bps, queue_packets=queue, **rest
    )


def test_a_constant_5_ms_latency_delivers_exactly_5_ms_after_sending(streams):
    net = network(streams, latency=ConstantLatency(5.0))
    for t in [0, 1, 999_999, 3 * MS, 3 * MS, 10**12 + 7]:
        assert net.transmit(t, "a", ["b"], 100, no_distance) == [
            ("b", DeliveryStatus.DELIVERED, t + 5 * MS)
        ]


def test_back_to_back_1250_byte_messages_at_1_mbit_s_arrive_10_ms_apart(streams):
    net = network(streams, bandwidth_bps=1e6)
    arrivals = [net.transmit(0, "a", ["b"], 1250, no_distance)[0][2] for _ in range(3)]
    assert arrivals == [10 * MS, 20 * MS, 30 * MS]


def test_serialization_and_latency_add_up(streams):
    net = network(streams, latency=ConstantLatency(2.5), bandwidth_bps=1e6)
    assert net.transmit(1 * MS, "a", ["b"], 125, no_distance) == [
        ("b", DeliveryStatus.DELIVERED, 4_500_000)
    ]


def _arrivals(net, n, gap_ns):
    out = []
    for k in range(n):
        [(_, fate, t)] = net.transmit(k * gap_ns, "a", ["b"], 100, no_distance)
        assert fate is DeliveryStatus.DELIVERED
        out.append(t)
    return np.array(out)


def test_a_fifo_link_never_reorders_messages_despite_jitter(streams):
    net = network(streams, latency=NormalLatency(5.0, 3.0))
    arrivals = _arrivals(net, 3000, 100_000)
    assert np.all(np.diff(arrivals) >= 0)


def test_a_reordering_link_lets_jitter_reorder_messages(streams):
    net = network(streams, latency=NormalLatency(5.0, 3.0), reorder=True)
    arrivals = _arrivals(net, 3000, 100_000)
    assert np.sum(np.diff(arrivals) < 0) > 100


def test_fifo_holds_back_a_message_only_until_the_previous_one_arrived(streams):
    net = network(streams, latency=NormalLatency(5.0, 3.0))
    free = network(streams, latency=NormalLatency(5.0, 3.0), reorder=True)
    held, jittered = _arrivals(net, 500, 100_000), _arrivals(free, 500, 100_000)
    assert held.tolist() == np.maximum.accumulate(jittered).tolist()


def test_loss_probability_1_drops_every_message_and_0_drops_none(streams):
    for p, fate in [(1.0, DeliveryStatus.LOST), (0.0, DeliveryStatus.DELIVERED)]:
        net = network(streams, loss=lambda p=p: BernoulliLoss(p))
        fates = {
            net.transmit(k, "a", ["b", "c"], 10, no_distance)[i][1]
            for k in range(2000)
            for i in (0, 1)
        }
        assert fates == {fate}


def test_a_partition_drops_exactly_the_messages_sent_inside_its_window(streams):
    cut = Partition(from_ns=10 * MS, to_ns=20 * MS, hosts=frozenset({"a"}))
    net = network(streams, partitions=[cut])
    partitioned = {"a->b": [], "b->a": [], "b->c": []}
    for t in range(0, 30 * MS, MS // 2):
        for src, dst in [("a", "b"), ("b", "a"), ("b", "c")]:
            [(_, fate, _)] = net.transmit(t, src, [dst], 10, no_distance)
            if fate is DeliveryStatus.PARTITIONED:
                partitioned[f"{src}->{dst}"].append(t)
            else:
                assert fate is DeliveryStatus.DELIVERED
    inside = list(range(10 * MS, 20 * MS, MS // 2))
    assert partitioned == {"a->b": inside, "b->a": inside, "b->c": []}


def test_a_partition_of_explicit_links_cuts_only_those_links(streams):
    cut = Partition(from_ns=0, to_ns=MS, links=frozenset({("c", "a")}))
    assert cut.links == {("a", "c")}
    net = network(streams, partitions=[cut])
    fates = [f for _, f, _ in net.transmit(0, "a", ["b", "c"], 10, no_distance)]
    assert fates == [DeliveryStatus.DELIVERED, DeliveryStatus.PARTITIONED]
    assert net.transmit(MS, "c", ["a"], 10, no_distance)[0][1] is DeliveryStatus.DELIVERED


def test_beyond_range_every_message_is_out_of_range_and_unknown_positions_are_not(streams):
    distances = {("a", "b"): 50.0, ("a", "c"): 50.001, ("a", "d"): None}
    net = network(streams, range_m=50.0)
    for k in range(200):
        out = net.transmit(k, "a", ["b", "c", "d"], 10, lambda s, d: distances[(s, d)])
        assert [f for _, f, _ in out] == [
            DeliveryStatus.DELIVERED,
            DeliveryStatus.OUT_OF_RANGE,
            DeliveryStatus.DELIVERED,
        ]


def test_reception_under_path_loss_falls_with_distance_as_the_model_predicts(streams):
    radio = PathLoss()
    hosts = {"d10": 10.0, "d50": 50.0, "d70": 70.0, "d90": 90.0, "d150": 150.0}
    net = network(streams, path_loss=radio, range_m=120.0)
    n = 3000
    received = dict.fromkeys(hosts, 0)
    fates = set()
    for k in range(n):
        for dst, fate, _ in net.transmit(k, "src", list(hosts), 10, lambda s, d: hosts[d]):
            received[dst] += fate is DeliveryStatus.DELIVERED
            fates.add((dst, fate))
    assert ("d150", DeliveryStatus.OUT_OF_RANGE) in fates and (
        "d150",
        DeliveryStatus.DELIVERED,
    ) not in fates
    rates = [received[h] / n for h in ["d10", "d50", "d70", "d90"]]
    assert rates == sorted(rates, reverse=True)
    for host in ["d10", "d50", "d70", "d90"]:
        p = radio.reception_probability_at(hosts[host])
        assert received[host] / n == pytest.approx(p, abs=4 * np.sqrt(p * (1 - p) / n) + 1e-9)


def test_pairs_outside_the_topology_are_out_of_range(streams):
    net = network(streams)
    net.set_edges(ring(["a", "b", "c", "d"]))
    out = net.transmit(0, "a", ["b", "c", "d"], 10, no_distance)
    assert [f for _, f, _ in out] == [
        DeliveryStatus.DELIVERED,
        DeliveryStatus.OUT_OF_RANGE,
        DeliveryStatus.DELIVERED,
    ]
    net.set_edges(None)
    out = net.transmit(0, "a", ["c"], 10, no_distance)
    assert out[0][1] is DeliveryStatus.DELIVERED


def test_a_full_queue_refuses_every_destination_with_exact_counts(streams):
    net = network(streams, bandwidth_bps=1e6, queue=2)
    fates = [net.transmit(0, "a", ["b", "c"], 1250, no_distance) for _ in range(5)]
    assert [[f for _, f, _ in out] for out in fates] == [[DeliveryStatus.DELIVERED] * 2] * 3 + [
        [DeliveryStatus.QUEUE_FULL] * 2
    ] * 2
    # another host's interface is not affected
    assert net.transmit(0, "b", ["a"], 1250, no_distance) == [
        ("a", DeliveryStatus.DELIVERED, 10 * MS)
    ]


def test_a_broadcast_is_serialized_once_for_all_receivers(streams):
    net = network(streams, bandwidth_bps=1e6)
    first = net.transmit(0, "a", ["b", "c", "d", "e"], 1250, no_distance)
    second = net.transmit(0, "a", ["b", "c"], 1250, no_distance)
    assert {t for _, _, t in first} == {10 * MS}
    assert {t for _, _, t in second} == {20 * MS}


def test_broadcast_receivers_lose_messages_independently(streams):
    net = network(streams, loss=lambda: BernoulliLoss(0.3))
    n = 5000
    lost = np.array(
        [
            [
                f is DeliveryStatus.LOST
                for _, f, _ in net.transmit(k, "a", ["b", "c"], 10, no_distance)
            ]
            for k in range(n)
        ]
    )
    assert lost.mean(axis=0) == pytest.approx([0.3, 0.3], abs=0.03)
    # independent receivers: correlation within 4 standard errors (1/sqrt(n)) of 0
    assert abs(np.corrcoef(lost[:, 0], lost[:, 1])[0, 1]) < 4 / np.sqrt(n)


def test_adding_a_host_does_not_change_another_links_fates(make_streams):
    def run(extra):
        params = {"latency": NormalLatency(5.0, 2.0), "loss": lambda: GilbertElliottLoss(0.1, 0.3)}
        net = network(make_streams(3), **params)
        seen = []
        for k in range(1000):
            t = k * MS
            if extra:
                net.transmit(t, "c", ["b", "a"], 10, no_distance)
            out = net.transmit(t, "a", ["c", "b"] if extra else ["b"], 10, no_distance)
            seen += [o for o in out if o[0] == "b"]
        return seen

    alone, crowded = run(False), run(True)
    assert alone == crowded
    assert {f for _, f, _ in alone} == {DeliveryStatus.DELIVERED, DeliveryStatus.LOST}


def test_each_directed_link_gets_its_own_stream_and_loss_process(make_streams):
    asked, made = [], []
    base = make_streams(1)

    def streams(name):
        asked.append(name)
        return base(name)

    def loss():
        made.append(GilbertElliottLoss(0.2, 0.2))
        return made[-1]

    net = network(streams, loss=loss)
    for k in range(600):  # more than one block of draws per link
        net.transmit(k, "a", ["b", "c"], 10, no_distance)
        net.transmit(k, "b", ["a"], 10, no_distance)
    assert asked == ["network/a->b", "network/a->c", "network/b->a"]
    assert len(made) == 3


def test_the_same_streams_give_the_same_run(make_streams):
    def run():
        net = network(
            make_streams(9),
            latency=NormalLatency(5.0, 2.0),
            loss=lambda: BernoulliLoss(0.2),
            bandwidth_bps=2e6,
            queue=3,
            path_loss=PathLoss(),
        )
        return [
            net.transmit(k * 100_000, "a", ["b", "c"], 500, lambda s, d: 60.0) for k in range(2000)
        ]

    assert run() == run()


def test_sending_to_oneself_through_the_network_is_a_bug(streams):
    with pytest.raises(ValueError, match="itself"):
        network(streams).transmit(0, "a", ["a"], 10, no_distance)


def test_impossible_network_parameters_are_refused_with_their_keys(streams):
    with pytest.raises(ModelError) as error:
        Partition(from_ns=5, to_ns=4)
    assert error.value.key == "network.partitions"
    with pytest.raises(ModelError) as error:
        Partition(from_ns=0, to_ns=4, links=frozenset({("a", "a")}))
    assert error.value.key == "network.partitions"
    with pytest.raises(ModelError) as error:
        network(streams, range_m=-1.0)
    assert error.value.key == "network.range_m"
    with pytest.raises(ModelError) as error:
        network(streams, bandwidth_bps=0.0)
    assert error.value.key == "network.bandwidth_mbps"
    with pytest.raises(ModelError) as error:
        network(streams, queue=-1)
    assert error.value.key == "network.queue_packets"


@pytest.mark.parametrize(("latency_ms", "reorder"), [(0.0, False), (3.5, False), (1.0, True)])
def test_an_ideal_network_delivers_as_its_links_would_without_drawing_them(
    make_streams, latency_ms, reorder
):
    """Forced through its links (every pair listed as an edge), the same network decides
    every copy the same way; unforced it asks for no random stream at all."""
    hosts = [f"h{i}" for i in range(6)]
    asked: list[list[str]] = [[], []]

    def counted(k):
        streams = make_streams(3)
        return lambda name: (asked[k].append(name), streams(name))[1]

    fast = network(counted(0), latency=ConstantLatency(latency_ms), reorder=reorder)
    forced = network(counted(1), latency=ConstantLatency(latency_ms), reorder=reorder)
    forced.set_edges(frozenset(complete(hosts)))
    rng = np.random.default_rng(5)
    t = 0
    for _ in range(600):  # more than a block of 256 draws on some links
        t += int(rng.integers(0, 3)) * MS
        src = hosts[int(rng.integers(len(hosts)))]
        dsts = [h for h in hosts if h != src and rng.random() < 0.8]
        outcome = fast.transmit(t, src, dsts, 100, no_distance)
        assert outcome == forced.transmit(t, src, dsts, 100, no_distance)
        assert outcome == [(d, DeliveryStatus.DELIVERED, t + round(latency_ms * MS)) for d in dsts]
    assert asked[0] == [] and len(asked[1]) == 30
    with pytest.raises(ValueError, match="cannot send to itself"):
        fast.transmit(t, "h0", ["h1", "h0"], 100, no_distance)


@pytest.mark.parametrize(
    "kwargs",
    [
        {"latency": NormalLatency(2.0, 0.5)},
        {"loss": lambda: BernoulliLoss(0.1)},
        {"range_m": 30.0},
        {"bandwidth_bps": 1e6},
        {"partitions": [Partition(0, MS, hosts=frozenset({"a"}))]},
    ],
)
def test_a_network_that_can_drop_delay_or_reorder_goes_through_its_links(streams, kwargs):
    net = network(streams, **kwargs)
    net.transmit(0, "a", ["b", "c"], 100, no_distance)
    assert len(net._links) == 2


@pytest.mark.parametrize(
    ("kwargs", "ideal"),
    [
        ({"latency": ConstantLatency(2.0)}, True),
        ({"latency": ConstantLatency(0.0), "reorder": True}, True),
        ({"latency": NormalLatency(2.0, 0.5)}, False),
        ({"loss": lambda: BernoulliLoss(0.3)}, False),
        ({"queue": 2, "bandwidth_bps": 1e4}, False),
    ],
)
def test_transmitting_to_all_at_once_stands_for_the_outcomes_transmit_lists(
    make_streams, kwargs, ideal
):
    """An ideal network answers one arrival time: every copy's, as the same network forced
    through its links (every pair listed as an edge) lists them."""
    hosts = [f"h{i}" for i in range(5)]
    at_once = network(make_streams(3), **kwargs)
    each = network(make_streams(3), **kwargs)
    each.set_edges(frozenset(complete(hosts)))
    rng = np.random.default_rng(2)
    t = 0
    for _ in range(300):
        t += int(rng.integers(0, 2)) * MS
        src = hosts[int(rng.integers(len(hosts)))]
        dsts = [h for h in hosts if h != src and rng.random() < 0.7]
        outcome = at_once.transmit_all(t, src, dsts, 100, no_distance)
        assert isinstance(outcome, int) is ideal
        expanded = (
            [(d, DeliveryStatus.DELIVERED, outcome) for d in dsts]
            if isinstance(outcome, int)
            else outcome
        )
        assert expanded == each.transmit(t, src, dsts, 100, no_distance)


def test_on_a_shared_channel_every_host_takes_its_turn_headers_and_overheads_included(streams):
    from models.network.model import FRAME_OVERHEAD_BYTES, FRAME_OVERHEAD_NS

    net = network(streams, airtime_bps=6e6)
    first = net.transmit(0, "a", ["b"], 1000, no_distance)[0][2]
    second = net.transmit(0, "c", ["b"], 1000, no_distance)[0][2]  # another host, same air
    one = (1000 + FRAME_OVERHEAD_BYTES) * 8 / 6e6 * 1e9 + FRAME_OVERHEAD_NS
    assert first == pytest.approx(one, abs=1500)  # the overhead is rounded to whole bytes
    assert second == 2 * first


def test_on_a_shared_channel_latency_grows_with_the_robots_sending(streams):
    def mean_delay(hosts: int) -> float:
        net = network(lambda name: np.random.default_rng(1), airtime_bps=6e6, queue=10_000)
        delays = []
        for k in range(20):  # every host sends 500 bytes at 10 Hz, all at once
            for h in range(hosts):
                t = k * 100 * MS
                delays.append(net.transmit(t, f"r{h}", ["base"], 500, no_distance)[0][2] - t)
        return float(np.mean(delays))

    # a 500-byte frame holds 6 Mbit/s air 0.87 ms: k-th of n in a burst waits k of them
    assert mean_delay(4) < mean_delay(20) < mean_delay(50)
    assert mean_delay(4) == pytest.approx(2.5 * 0.868 * MS, rel=0.01)
    assert mean_delay(50) == pytest.approx(25.5 * 0.868 * MS, rel=0.01)


def test_a_shared_channel_and_per_host_bandwidth_are_not_combined(streams):
    with pytest.raises(ModelError, match="airtime_mbps"):
        network(streams, bandwidth_bps=1e6, airtime_bps=6e6)

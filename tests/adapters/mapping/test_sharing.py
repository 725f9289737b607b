from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np
import pytest

import cosim
from adapters.mapping.contract import SharingContext
from adapters.mapping.geometry import map_geometry
from adapters.mapping.mapper import mapper_params
from adapters.mapping.settings import MappingConfig
from adapters.mapping.sharing import MapUpdateSharing, NoSharing, ScanSharing
from adapters.mapping.tables import MappingRecords
from adapters.mapping.topics import SCANS, UPDATES
from cosim.core.adapter import RunContext
from cosim.core.bus import Bus, TopicQos
from cosim.core.hosts import HostId
from cosim.core.kernel import Kernel
from cosim.core.link import DELIVERED, Transfer
from cosim.core.messages import LaserScan, LocalizedScan, MapUpdate, Message
from cosim.core.recorder import Recorder
from cosim.core.rng import RngStreams
from cosim.core.timebase import s_to_ns
from cosim.recording.dataframes import table_frame
from cosim.runner.assembly import assemble
from models.mapping.exchange import pack
from models.mapping.grid import LogOddsMap
from models.world.warehouse import Warehouse
from tests.conftest import SMALL

NAMES = ["robot_1", "robot_2", "robot_3"]
LATENCY_NS = 30_000_000
POSE = (3.0, 3.0, 0.0)
"""Where robot_1 maps its scan: a wall 2 m ahead (m, rad in ``map``)."""


@dataclass
class Network:
    """30 ms to every host, or nothing at all."""

    lossy: bool = False

    def transmit(
        self, t_ns: int, src: HostId, dsts: Sequence[HostId], nbytes: int, topic: str
    ) -> list[Transfer]:
        if self.lossy:
            return [Transfer(d, "lost", None) for d in dsts]
        return [Transfer(d, DELIVERED, t_ns + LATENCY_NS) for d in dsts]


@pytest.fixture(scope="module")
def world() -> Warehouse:
    scenario = cosim.load_scenario("warehouse-random", SMALL)
    return assemble(scenario, names=["world"]).run.service(Warehouse)


def context(world: Warehouse, share: str, lossy: bool = False, **mapping: object) -> SharingContext:
    kernel = Kernel()
    recorder = Recorder()
    run = RunContext(None, kernel, Bus(kernel, Network(lossy), recorder), RngStreams(1), recorder)  # type: ignore[arg-type]
    cfg = replace(MappingConfig(), enabled=True, share=share, **mapping)  # type: ignore[arg-type]
    geometry = map_geometry(world, 0.1)
    tracks = share == "maps"
    maps = [LogOddsMap(geometry, track_changes=tracks) for _ in NAMES]
    return SharingContext(
        run,
        cfg,
        NAMES,
        [HostId(n) for n in NAMES],
        maps,
        geometry,
        mapper_params(cfg, 0.1, 10.0),
        MappingRecords(recorder, NAMES, world, geometry),
    )


def scan(stamp_ns: int = 0) -> LaserScan:
    ranges = np.full(41, 2.0, dtype=np.float32)
    return LaserScan(stamp_ns, "robot_1/laser", -0.4, 0.02, 0.1, 10.0, 0.1, ranges)


def published(run: RunContext, topic: str) -> list[tuple[Message, str]]:
    seen: list[tuple[Message, str]] = []
    run.bus.monitor(topic, lambda _t, message, src, _now: seen.append((message, src)))
    return seen


def integrate(grid: LogOddsMap, pose: tuple[float, float, float], s: LaserScan) -> int:
    angles = s.angle_min_rad + s.angle_increment_rad * np.arange(len(s.ranges_m))
    return grid.integrate(
        pose, angles, s.ranges_m, range_min_m=0.1, range_max_m=10.0, clear_no_return_m=3.0
    )


def test_without_sharing_nothing_is_advertised_sent_or_received(world):
    ctx = context(world, "none")
    mode = NoSharing(ctx)
    mode.start(ctx.run)
    mode.mapped(ctx.run, 0, POSE, scan())
    assert ctx.run.bus.advertised() == {}
    assert ctx.run.bus.subscribers(SCANS) == [] and ctx.run.bus.subscribers(UPDATES) == []
    assert ctx.records.shared_messages == 0


def test_a_mapped_scan_goes_to_the_neighbours_with_its_estimated_pose(world):
    ctx = context(world, "scans")
    mode = ScanSharing(ctx)
    assert ctx.run.bus.advertised()[SCANS].qos is TopicQos.SENSOR
    mode.start(ctx.run)
    sent = published(ctx.run, SCANS)
    ctx.run.kernel.run(s_to_ns(1.0))
    s = scan(stamp_ns=s_to_ns(0.9))
    mode.mapped(ctx.run, 0, POSE, s)
    [(message, src)] = sent
    assert src == "robot_1"
    assert isinstance(message, LocalizedScan)
    assert (message.robot, message.stamp_ns) == ("robot_1", s_to_ns(1.0))
    assert (message.x_m, message.y_m, message.yaw_rad) == POSE
    assert (message.angle_min_rad, message.angle_increment_rad) == (-0.4, 0.02)
    assert (message.range_min_m, message.range_max_m) == (0.1, 10.0)
    assert np.array_equal(message.ranges_m, s.ranges_m)
    assert (ctx.records.shared_messages, ctx.records.shared_bytes) == (1, message.size_bytes())


def test_the_neighbours_map_a_shared_scan_at_the_senders_pose_and_record_the_merge(world):
    ctx = context(world, "scans")
    mode = ScanSharing(ctx)
    mode.start(ctx.run)
    mode.mapped(ctx.run, 0, POSE, scan())
    reference = LogOddsMap(ctx.geometry)
    integrate(reference, POSE, scan())
    ctx.run.kernel.run(s_to_ns(0.1))
    assert ctx.maps[0].empty  # its own scan is the mapper's to add, not the sharing's
    for neighbour in ctx.maps[1:]:
        assert np.array_equal(neighbour.logodds, reference.logodds)
    merges = table_frame(ctx.records.merges)
    assert list(merges.robot) == ["robot_2", "robot_3"]
    assert list(merges.source) == ["robot_1", "robot_1"] and set(merges.kind) == {"scan"}
    assert list(merges.delay_s) == [0.03, 0.03]
    assert (merges.cells > 0).all()


def test_a_lost_scan_is_not_sent_again_and_its_evidence_is_lost(world):
    ctx = context(world, "scans", lossy=True)
    mode = ScanSharing(ctx)
    mode.start(ctx.run)
    mode.mapped(ctx.run, 0, POSE, scan())
    ctx.run.kernel.run(s_to_ns(5.0))
    assert all(grid.empty for grid in ctx.maps)
    assert ctx.records.shared_messages == 1 and ctx.records.merged == 0


def test_map_updates_send_what_a_robots_own_scans_added_every_share_period(world):
    ctx = context(world, "maps", share_period_s=2.0)
    mode = MapUpdateSharing(ctx)
    assert ctx.run.bus.advertised()[UPDATES].message_type is MapUpdate
    mode.start(ctx.run)
    sent = published(ctx.run, UPDATES)
    integrate(ctx.maps[0], POSE, scan())
    mode.mapped(ctx.run, 0, POSE, scan())  # nothing at once
    assert sent == []
    ctx.run.kernel.run(s_to_ns(2.1))
    [(update, src)] = sent
    assert src == "robot_1" and isinstance(update, MapUpdate)
    assert (update.robot, update.seq, update.stamp_ns) == ("robot_1", 1, s_to_ns(2.0))
    assert (ctx.records.shared_messages, ctx.records.shared_bytes) == (1, update.size_bytes())
    for neighbour in ctx.maps[1:]:
        # the same evidence, to the int8 quantization of the update
        assert np.abs(neighbour.logodds - ctx.maps[0].logodds).max() <= update.scale / 2 + 1e-6
        assert not neighbour.empty
    merges = table_frame(ctx.records.merges)
    assert list(merges.robot) == ["robot_2", "robot_3"] and set(merges.kind) == {"map"}
    ctx.run.kernel.run(s_to_ns(6.1))  # nothing new: nothing sent
    assert len(sent) == 1


def test_the_next_update_carries_only_what_was_added_since_and_counts_on(world):
    ctx = context(world, "maps", share_period_s=1.0)
    mode = MapUpdateSharing(ctx)
    mode.start(ctx.run)
    sent = published(ctx.run, UPDATES)
    integrate(ctx.maps[1], POSE, scan())
    ctx.run.kernel.run(s_to_ns(1.5))
    integrate(ctx.maps[1], (3.0, 3.0, 1.0), scan())
    ctx.run.kernel.run(s_to_ns(2.5))
    assert [(u.robot, u.seq) for u, _ in sent] == [("robot_2", 1), ("robot_2", 2)]
    assert ctx.maps[1].take_changes() is None  # everything was sent


def test_a_malformed_update_is_refused_as_an_event_and_changes_no_map(world):
    ctx = context(world, "maps")
    mode = MapUpdateSharing(ctx)
    mode.start(ctx.run)
    changes = np.zeros((ctx.geometry.height, ctx.geometry.width), dtype=np.float32)
    changes[5:8, 5:9] = 1.0
    packed = pack(changes)
    assert packed is not None
    bad = MapUpdate(
        0,
        "robot_2",
        1,
        packed.ix0,
        packed.iy0,
        packed.width + 1,
        packed.height,
        packed.scale,
        data=packed.data,
    )
    ctx.run.bus.publish(UPDATES, bad, HostId("robot_2"))
    ctx.run.kernel.run(s_to_ns(0.1))
    events = table_frame(ctx.run.recorder.events)
    assert list(events.source) == ["robot_1", "robot_3"]
    assert set(events.kind) == {"map_update_refused"}
    inflated, expected = packed.width * packed.height, (packed.width + 1) * packed.height
    assert events.detail.iloc[0] == f"map update = {inflated}: expected {expected} cells"
    assert all(grid.empty for grid in ctx.maps) and ctx.records.merged == 0


def test_map_updates_refuse_loop_closure_naming_both_keys():
    cfg = replace(MappingConfig(), enabled=True, share="maps", loop_closure=True)
    [problem] = list(MapUpdateSharing.problems(cfg))
    assert (problem.key, problem.value) == ("loop_closure", True)
    assert list(MapUpdateSharing.problems(replace(cfg, loop_closure=False))) == []


def test_loop_closure_with_shared_map_updates_is_refused_naming_the_keys():
    with pytest.raises(cosim.ConfigError, match=r"\[mapping\] loop_closure = true: expected false"):
        cosim.load_scenario(
            "warehouse-mapping", overrides={"mapping.loop_closure": True, "mapping.share": "maps"}
        )


def test_loop_closure_with_shared_scans_is_accepted():
    s = cosim.load_scenario(
        "warehouse-mapping", overrides={"mapping.loop_closure": True, "mapping.share": "scans"}
    )
    assert s.section(MappingConfig).share == "scans"

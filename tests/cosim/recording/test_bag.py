"""A run's bag: read by an independent reader, counts and stamps as the run had them."""

import math
import os
import shutil
import signal
import subprocess
import sys
import time

import numpy as np
import pytest
import yaml
from mcap.stream_reader import StreamReader
from rosbags.highlevel import AnyReader
from rosbags.rosbag2 import StoragePlugin, Writer

import cosim
from cosim.core.bus import TopicQos
from cosim.core.timebase import NS_PER_S
from cosim.recording.bag import BagSink, _StreamingWriter
from cosim.recording.schemas import ChannelSpec, definition, offered_qos
from cosim.testing.outcomes import VOLATILE
from tests.bags import TASKS, mcap_file, read_mcap
from tests.conftest import SMALL

ROBOTS = [f"robot_{i}" for i in (1, 2, 3)]


def test_every_topic_of_the_bag_decodes_with_the_schemas_it_embeds(task_bag):
    assert task_bag.profile == "ros2"
    custom = {t for t, name in task_bag.types.items() if name.startswith("cosim_msgs/")}
    assert {"/fleet/tasks", "/fleet/claims", "/fleet/assignment", "/robot_1/nav/status"} <= custom
    assert task_bag.types["/robot_1/scan"] == "sensor_msgs/msg/LaserScan"
    assert task_bag.types["/tf"] == "tf2_msgs/msg/TFMessage"
    assert task_bag.types["/map"] == "nav_msgs/msg/OccupancyGrid"
    assert task_bag.types["/world/markers"] == "visualization_msgs/msg/MarkerArray"
    assert task_bag.types["/robot_1/plan"] == "nav_msgs/msg/Path"
    assert task_bag.types["/robot_1/ground_truth"] == "nav_msgs/msg/Odometry"
    assert task_bag.types["/clock"] == "rosgraph_msgs/msg/Clock"
    # decoded objects, not raw bytes, for every message of every topic
    for topic, messages in task_bag.messages.items():
        assert messages, topic
        assert all(not isinstance(m, bytes | bytearray) for m in messages), topic


def test_counts_agree_with_the_run(task_run, task_bag):
    scenario = task_run.scenario
    duration = scenario.scenario.duration_s
    scans_per_robot = round(scenario.lidar.rate_hz * duration)
    odom_per_robot = round(scenario.robots.control_hz * duration)
    samples = round(scenario.record.pose_rate_hz * duration)
    for robot in ROBOTS:
        assert len(task_bag.messages[f"/{robot}/scan"]) == scans_per_robot
        assert len(task_bag.messages[f"/{robot}/odom"]) == odom_per_robot
        assert len(task_bag.messages[f"/{robot}/ground_truth"]) == samples
    assert len(task_bag.messages["/clock"]) == samples
    assert len(task_bag.messages["/tf"]) == samples
    assert len(task_bag.messages["/tf_static"]) == len(task_bag.messages["/map"]) == 1
    # what the tap counted is what the bag holds
    recorded = {t: n for t, n in task_run.recorded.items() if n}
    assert recorded == {t: len(m) for t, m in task_bag.messages.items()}
    # the same number of protocol decisions as the assignments table shows
    navigation = task_run.tables["navigation"]
    goals = navigation[navigation.event == "goal"]
    assert len(task_bag.messages["/robot_1/nav/goal"]) == (goals.robot == "robot_1").sum()


def _stamp_ns(message) -> int:
    header = getattr(message, "header", None)
    stamp = header.stamp if header is not None else message.clock
    return stamp.sec * NS_PER_S + stamp.nanosec


def test_stamps_are_monotonic_per_topic_and_equal_the_simulation_clock(task_bag):
    for topic, log_ns in task_bag.log_ns.items():
        assert log_ns == sorted(log_ns), topic
        assert log_ns[0] >= 0 and log_ns[-1] < 6 * NS_PER_S, topic
    stamped = [t for t in task_bag.messages if t not in ("/tf", "/tf_static", "/world/markers")]
    for topic in stamped:
        for message, log_ns in zip(task_bag.messages[topic], task_bag.log_ns[topic], strict=True):
            assert _stamp_ns(message) == log_ns, topic
    # /clock ticks exactly at the pose rate: 10 Hz is 100,000,000 ns
    assert task_bag.log_ns["/clock"] == [k * 100_000_000 for k in range(60)]
    for message, log_ns in zip(task_bag.messages["/tf"], task_bag.log_ns["/tf"], strict=True):
        assert {_stamp_ns(t) for t in message.transforms} == {log_ns}


def test_frames_chain_map_odom_base_link_laser_for_every_robot(task_bag):
    parents = {}
    for message in (task_bag.messages["/tf"][0], task_bag.messages["/tf_static"][0]):
        for t in message.transforms:
            parents[t.child_frame_id] = t.header.frame_id
    for robot in ROBOTS:
        assert parents[f"{robot}/laser"] == f"{robot}/base_link"
        assert parents[f"{robot}/base_link"] == f"{robot}/odom"
        assert parents[f"{robot}/odom"] == "map"
    scan = task_bag.messages["/robot_2/scan"][0]
    odom = task_bag.messages["/robot_2/odom"][0]
    assert scan.header.frame_id == "robot_2/laser"
    assert (odom.header.frame_id, odom.child_frame_id) == ("robot_2/odom", "robot_2/base_link")


def test_ground_truth_in_the_bag_is_the_poses_table(task_run, task_bag):
    poses = task_run.tables["poses"]
    first = poses[poses.robot == "robot_3"].iloc[-1]
    truth = task_bag.messages["/robot_3/ground_truth"][-1]
    assert truth.header.frame_id == "map"
    assert truth.pose.pose.position.x == pytest.approx(first.x_m)
    assert truth.pose.pose.position.y == pytest.approx(first.y_m)
    q = truth.pose.pose.orientation
    assert math.remainder(2 * math.atan2(q.z, q.w) - first.yaw_rad, 2 * math.pi) == pytest.approx(
        0.0, abs=1e-9
    )


def test_scans_follow_rep_117_and_match_the_lidar_settings(task_run, task_bag):
    lidar = task_run.scenario.lidar
    scan = task_bag.messages["/robot_1/scan"][5]
    ranges = np.asarray(scan.ranges)
    assert len(ranges) == lidar.beams
    assert scan.range_max == pytest.approx(lidar.range_max_m)
    finite = ranges[np.isfinite(ranges)]
    assert finite.size and (finite <= lidar.range_max_m + 0.1).all()
    # beams without a return are +inf, never a made-up maximum
    assert not (ranges == lidar.range_max_m).any()


def test_latched_topics_are_recorded_transient_local_and_the_others_replay_as_default(task_run):
    meta = yaml.safe_load((task_run.bag / "metadata.yaml").read_text())
    info = meta["rosbag2_bagfile_information"]
    assert info["version"] == 8
    assert info["storage_identifier"] == "mcap"
    qos = {
        t["topic_metadata"]["name"]: yaml.safe_load(t["topic_metadata"]["offered_qos_profiles"])
        for t in info["topics_with_message_count"]
    }
    for topic in ("/map", "/tf_static", "/world/markers"):
        assert qos[topic][0]["durability"] == 1  # transient local
        assert qos[topic][0]["reliability"] == 1  # reliable
    # no profile: `ros2 bag play` offers its default, which every subscriber matches
    assert qos["/robot_1/scan"] is None and qos["/robot_1/odom"] is None


def test_the_default_topics_leave_out_velocity_commands_and_protocol_rounds(task_bag):
    assert not any(t.endswith("/cmd_vel") for t in task_bag.messages)
    assert not any(t.startswith("/fleet/dta/") for t in task_bag.messages)


def test_record_topics_choose_what_the_bag_keeps(tmp_path):
    overrides = {**SMALL, "scenario.duration_s": 1.0, "record.topics": ["/robot_*/scan", "/clock"]}
    result = cosim.run(cosim.load_scenario("warehouse-random", overrides=overrides), out=tmp_path)
    bag = read_mcap(mcap_file(result.bag))
    assert set(bag.messages) == {"/clock", *(f"/{r}/scan" for r in ROBOTS)}


def test_tables_are_the_same_with_and_without_a_bag(tmp_path):
    scenario = cosim.load_scenario("warehouse-random", overrides=TASKS)
    with_bag = cosim.run(scenario, out=tmp_path / "bag")
    without = cosim.run(scenario)
    assert with_bag.bag is not None and without.bag is None
    for name, frame in without.deterministic_tables().items():
        assert with_bag.deterministic_tables()[name].equals(frame), name
    machine = {*VOLATILE, "plugins"}
    assert {k: v for k, v in with_bag.summary.items() if k not in machine} == {
        k: v for k, v in without.summary.items() if k not in machine
    }
    # the bag's run also ran the ROS interface that fills it, and says so
    extra = [p for p in with_bag.summary["plugins"] if p not in without.summary["plugins"]]
    assert [(p["group"], p["name"]) for p in extra] == [("cosim.adapters", "ros_interface")]


def test_a_sqlite3_bag_with_compressed_messages_reads_back(tmp_path):
    overrides = {**SMALL, "scenario.duration_s": 1.0, "record.bag": "sqlite3"}
    result = cosim.run(cosim.load_scenario("warehouse-random", overrides=overrides), out=tmp_path)
    assert [p.suffix for p in result.bag.iterdir() if p.suffix != ".yaml"] == [".db3"]
    with AnyReader([result.bag]) as reader:
        scans = [c for c in reader.connections if c.topic == "/robot_1/scan"]
        decoded = [reader.deserialize(raw, c.msgtype) for c, _, raw in reader.messages(scans)]
    assert len(decoded) == 10
    assert len(decoded[0].ranges) == SMALL["lidar.beams"]


def test_no_bag_is_written_with_bag_none_or_without_a_folder(tmp_path):
    overrides = {**SMALL, "scenario.duration_s": 0.5, "record.bag": "none"}
    result = cosim.run(cosim.load_scenario("warehouse-random", overrides=overrides), out=tmp_path)
    assert result.bag is None and not (tmp_path / "bag").exists()
    assert cosim.run(cosim.load_scenario("warehouse-random", overrides=SMALL)).bag is None


def test_the_streaming_mcap_writer_writes_the_bytes_rosbags_writes(tmp_path):
    text, digest = definition("nav_msgs/msg/Odometry")
    qos = [offered_qos(TopicQos.DEFAULT)]
    payloads = [bytes([i % 251]) * (100 + i) for i in range(3000)]
    files = []
    for name, kind in (("ours", _StreamingWriter), ("rosbags", Writer)):
        # the same bag name: the file names its own path in its metadata
        writer = kind(tmp_path / name / "bag", version=8, storage_plugin=StoragePlugin.MCAP)
        writer.open()
        connections = [
            writer.add_connection(
                f"/r{i}/odom",
                "nav_msgs/msg/Odometry",
                msgdef=text,
                rihs01=digest,
                offered_qos_profiles=qos,
            )
            for i in range(3)
        ]
        for i, data in enumerate(payloads):
            writer.write(connections[i % 3], 1000 * i, data)
        writer.close()
        files.append((tmp_path / name / "bag" / "bag.mcap").read_bytes())
    assert files[0] == files[1]


def test_a_bag_that_exists_already_is_refused_with_its_path(tmp_path):
    (tmp_path / "bag").mkdir()
    sink = BagSink(tmp_path / "bag", storage="mcap", compression="none")
    text, digest = definition("rosgraph_msgs/msg/Clock")
    with pytest.raises(cosim.ExportError, match="bag"):
        sink.open(
            [ChannelSpec("/clock", "rosgraph_msgs/msg/Clock", text, digest, TopicQos.DEFAULT)]
        )


@pytest.mark.slow
def test_a_run_killed_mid_way_leaves_a_bag_whose_finished_chunks_read(tmp_path):
    out = tmp_path / "killed"
    command = [
        sys.executable,
        "-m",
        "cosim",
        "run",
        "fleet50",
        "--out",
        str(out),
        "--duration-s",
        "600",
        "--quiet",
    ]
    process = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    try:
        deadline = time.monotonic() + 120
        target = out / "bag" / "bag.mcap"
        while time.monotonic() < deadline:
            if target.exists() and target.stat().st_size > 3 * 2**20:
                break
            assert process.poll() is None, process.stderr.read() if process.stderr else ""
            time.sleep(0.2)
        os.kill(process.pid, signal.SIGKILL)
    finally:
        process.wait(timeout=30)
    assert not (out / "bag" / "metadata.yaml").exists()  # no clean close happened
    copy = tmp_path / "copy.mcap"
    shutil.copy(target, copy)
    messages = 0
    scans = 0
    with copy.open("rb") as stream:
        try:
            for record in StreamReader(stream, skip_magic=False).records:
                if type(record).__name__ == "Message":
                    messages += 1
                if type(record).__name__ == "Channel" and record.topic == "/robot_1/scan":
                    scans = record.id
        except Exception:  # the torn last chunk ends the stream; what came before counts
            pass
    assert scans and messages > 1000
    done = subprocess.run(
        [sys.executable, "-m", "cosim", "bag", "info", str(out / "bag")],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert done.returncode == 2
    assert done.stderr.count("\n") == 1 and "unfinished bag" in done.stderr
    assert "Traceback" not in done.stderr


@pytest.mark.slow
def test_our_bag_and_a_bag_written_by_rosbag2_read_through_one_code_path(task_run, nav2_bag):
    ours = read_mcap(mcap_file(task_run.bag))
    theirs = read_mcap(nav2_bag)
    assert theirs.profile == ours.profile == "ros2"
    assert theirs.types["/odom"] == ours.types["/robot_1/odom"] == "nav_msgs/msg/Odometry"
    assert theirs.types["/tf"] == ours.types["/tf"] == "tf2_msgs/msg/TFMessage"
    # the same decoded shapes: frames and stamps where rosbag2 puts them
    for bag, topic in ((ours, "/robot_1/odom"), (theirs, "/odom")):
        message = bag.messages[topic][0]
        assert message.header.frame_id and message.child_frame_id
        assert _stamp_ns(message) > 0 or bag is ours
    assert len(theirs.messages["/odom"]) == 2639
    # both carry rosbag2's QoS metadata on every channel
    for bag in (ours, theirs):
        assert all("offered_qos_profiles" in meta for meta in bag.channel_metadata.values())


def test_the_same_scenario_and_seed_write_byte_identical_bags(task_run, tmp_path):
    again = cosim.run(task_run.scenario, out=tmp_path / "again")
    for name in ("bag.mcap", "metadata.yaml"):
        assert (again.bag / name).read_bytes() == (task_run.bag / name).read_bytes(), name

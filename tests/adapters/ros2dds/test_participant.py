"""RosParticipant: ROS 2 topics over Cyclone DDS on loopback, within one process."""

import random
import time
from dataclasses import dataclass

import pytest
from cyclonedds.idl import IdlStruct
from cyclonedds.idl.annotations import final

from adapters.ros2dds.participant import RosParticipant
from adapters.ros2dds.qos import QosKind
from adapters.ros2dds.types import Header, LaserScan, PoseStamped, Time, Twist, Vector3
from cosim.core.errors import BridgeError

WAIT_S = 5.0


@final
@dataclass
class String(IdlStruct, typename="std_msgs::msg::dds_::String_"):
    data: str = ""


@final
@dataclass
class NotAPose(IdlStruct, typename="geometry_msgs::msg::dds_::PoseStamped_"):
    """A type that claims PoseStamped's name with another layout."""

    data: str = ""


@pytest.fixture
def domain() -> int:
    """A domain of its own, so that concurrent test runs on this machine never meet."""
    return random.SystemRandom().randint(1, 200)


def _exchange(publisher, subscription, sample, *, attempts=100):
    """Publish until something arrives (discovery takes a moment); return what arrived."""
    for _ in range(attempts):
        publisher.publish(sample)
        time.sleep(0.02)
        received = subscription.take()
        if received:
            return received
    return []


def _until(condition, timeout_s=WAIT_S):
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        if condition():
            return True
        time.sleep(0.02)
    return False


def test_two_participants_exchange_a_twist(domain):
    with RosParticipant(domain) as robot, RosParticipant(domain) as driver:
        commands = robot.subscription("/robot_0/cmd_vel", Twist, QosKind.DEFAULT)
        cmd_vel = driver.publisher("/robot_0/cmd_vel", Twist, QosKind.DEFAULT)
        twist = Twist(linear=Vector3(x=0.5), angular=Vector3(z=-0.25))
        received = _exchange(cmd_vel, commands, twist)
        assert received and all(sample == twist for sample in received)
        assert commands.received == len(received)
        assert commands.malformed == 0


def test_two_participants_exchange_a_laser_scan(domain):
    scan = LaserScan(
        header=Header(stamp=Time(sec=5, nanosec=7), frame_id="robot_0/laser"),
        angle_min=-1.5,
        angle_max=1.5,
        angle_increment=0.75,
        range_max=10.0,
        ranges=[1.0, 2.0, 3.0, 4.0, 5.0],
    )
    with RosParticipant(domain) as robot, RosParticipant(domain) as cosim:
        scans = robot.subscription("/robot_0/scan", LaserScan, QosKind.SENSOR_DATA)
        out = cosim.publisher("/robot_0/scan", LaserScan, QosKind.SENSOR_DATA)
        assert _exchange(out, scans, scan)[0] == scan


def test_a_best_effort_subscriber_receives_from_a_reliable_writer(domain):
    with RosParticipant(domain) as a, RosParticipant(domain) as b:
        best_effort = b.subscription("/robot_0/pose", PoseStamped, QosKind.SENSOR_DATA)
        reliable = a.publisher("/robot_0/pose", PoseStamped, QosKind.DEFAULT)
        assert _exchange(reliable, best_effort, PoseStamped())


def test_a_reliable_subscriber_never_receives_from_a_best_effort_writer(domain):
    with RosParticipant(domain) as a, RosParticipant(domain) as b:
        reliable = b.subscription("/robot_0/pose", PoseStamped, QosKind.DEFAULT)
        witness = b.subscription("/robot_0/pose", PoseStamped, QosKind.SENSOR_DATA)
        best_effort = a.publisher("/robot_0/pose", PoseStamped, QosKind.SENSOR_DATA)
        assert _exchange(best_effort, witness, PoseStamped())  # discovered, data flows
        assert reliable.take() == []


def test_take_returns_nothing_when_nothing_arrived(domain):
    with RosParticipant(domain) as ros:
        assert ros.subscription("/robot_0/scan", LaserScan, QosKind.SENSOR_DATA).take() == []


def test_a_sample_that_does_not_decode_is_counted_and_skipped(domain):
    # A C++ node may put any bytes in a string; Cyclone checks CDR lengths (a bad length
    # is refused by the writer and the reader) but not UTF-8, which Python then rejects.
    with RosParticipant(domain) as robot, RosParticipant(domain) as other:
        poses = robot.subscription("/robot_0/pose", PoseStamped, QosKind.DEFAULT)
        out = other.publisher("/robot_0/pose", PoseStamped, QosKind.DEFAULT)
        good = PoseStamped(header=Header(frame_id="map"))
        assert _exchange(out, poses, good)
        wire = good.serialize()
        assert wire[16:19] == b"map"  # CDR header, stamp, string length, then the string
        broken = PoseStamped()
        broken.serialize = lambda **_: wire[:16] + b"\xff\xfe\x00" + wire[19:]
        out.publish(good)
        out.publish(broken)
        out.publish(good)
        received = []
        assert _until(lambda: received.extend(poses.take()) or len(received) >= 2)
        assert received == [good, good]
        assert poses.malformed == 1


def test_cyclone_never_delivers_a_type_of_the_same_name_with_another_layout(domain):
    with RosParticipant(domain) as robot, RosParticipant(domain) as other:
        poses = robot.subscription("/robot_0/pose", PoseStamped, QosKind.DEFAULT)
        witness = robot.subscription("/robot_0/pose", NotAPose, QosKind.DEFAULT)
        impostor = other.publisher("/robot_0/pose", NotAPose, QosKind.DEFAULT)
        assert _exchange(impostor, witness, NotAPose("not a pose"))  # discovered, data flows
        assert poses.take() == []
        assert poses.malformed == 0


def test_a_writer_of_another_type_on_a_topic_is_counted_as_foreign(domain):
    expected = "geometry_msgs/msg/PoseStamped"
    with RosParticipant(domain) as robot:
        robot.subscription("/robot_0/pose", PoseStamped, QosKind.SENSOR_DATA)
        robot.publisher("/robot_0/pose", String, QosKind.SENSOR_DATA)  # its own: not foreign
        with RosParticipant(domain) as other:
            other.publisher("/robot_0/pose", String, QosKind.SENSOR_DATA)
            other.publisher("/robot_0/pose", PoseStamped, QosKind.SENSOR_DATA)
            other.publisher("/robot_1/pose", String, QosKind.SENSOR_DATA)
            assert _until(lambda: robot.foreign_writers("/robot_0/pose", expected) == 1)
            time.sleep(0.2)
            assert robot.foreign_writers("/robot_0/pose", expected) == 1
        assert _until(lambda: robot.foreign_writers("/robot_0/pose", expected) == 0)


@pytest.mark.parametrize("bad", [300, 233, -1])
def test_a_domain_out_of_range_raises_a_bridge_error_naming_it(bad):
    with pytest.raises(BridgeError, match=rf"domain {bad} is out of range; expected 0\.\.232"):
        RosParticipant(bad)


def test_an_unknown_interface_name_raises_a_bridge_error_naming_it(domain):
    with pytest.raises(BridgeError, match=r"interface 'nosuch0' does not exist.* lo"):
        RosParticipant(domain, interface="nosuch0")


def test_an_address_of_no_interface_raises_a_bridge_error_naming_it(domain):
    with pytest.raises(BridgeError, match=rf"domain {domain} on interface '192\.0\.2\.254'"):
        RosParticipant(domain, interface="192.0.2.254")


def test_one_domain_cannot_have_two_network_configurations_in_one_process(domain):
    with (
        RosParticipant(domain, interface="lo"),
        pytest.raises(BridgeError, match=f"domain {domain} is already open"),
    ):
        RosParticipant(domain)
    with RosParticipant(domain):  # the domain went with its last participant
        pass


def test_a_closed_participant_refuses_further_use(domain):
    with RosParticipant(domain) as ros:
        cmd_vel = ros.publisher("/robot_0/cmd_vel", Twist, QosKind.DEFAULT)
        scans = ros.subscription("/robot_0/scan", LaserScan, QosKind.SENSOR_DATA)
    with pytest.raises(BridgeError, match="closed"):
        cmd_vel.publish(Twist())
    with pytest.raises(BridgeError, match="closed"):
        scans.take()
    with pytest.raises(BridgeError, match="closed"):
        ros.publisher("/robot_0/cmd_vel", Twist, QosKind.DEFAULT)
    with pytest.raises(BridgeError, match="closed"):
        ros.foreign_writers("/robot_0/pose", "geometry_msgs/msg/PoseStamped")


def test_an_invalid_topic_name_is_a_value_error(domain):
    with RosParticipant(domain) as ros, pytest.raises(ValueError, match="robot-0"):
        ros.publisher("/robot-0/cmd_vel", Twist, QosKind.DEFAULT)

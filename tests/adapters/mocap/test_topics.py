import cosim
from adapters.mocap.topics import pose_topic
from adapters.ros2dds.naming import dds_topic
from cosim.core.messages import PoseStamped
from cosim.runner.assembly import assemble
from tests.conftest import SMALL


def test_a_robots_measured_poses_are_on_its_pose_topic():
    assert pose_topic("robot_1") == "/robot_1/pose"
    assert dds_topic(pose_topic("robot_12")) == "rt/robot_12/pose"


def test_pose_topics_of_different_robots_differ():
    names = [f"robot_{i}" for i in range(1, 30)]
    assert len({pose_topic(name) for name in names}) == len(names)


def test_the_mocap_source_advertises_each_tracked_robots_pose_topic_as_pose_stamped():
    overrides = {**SMALL, "mocap.source": "simulated", "mocap.robots": ["robot_1", "robot_3"]}
    advertised = assemble(cosim.load_scenario("warehouse-random", overrides)).run.bus.advertised()
    poses = {t: ad.message_type for t, ad in advertised.items() if t.endswith("/pose")}
    assert poses == {pose_topic("robot_1"): PoseStamped, pose_topic("robot_3"): PoseStamped}

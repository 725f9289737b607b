import cosim
from adapters.mapping.topics import FLEET_MAP, SCANS, UPDATES, correction_topic, map_topic
from adapters.ros2dds.naming import dds_topic
from cosim.core.bus import TopicQos
from cosim.core.messages import LocalizedScan, MapUpdate, OccupancyGrid, TFMessage
from cosim.runner.assembly import assemble
from tests.conftest import SMALL

MAPPING = {**SMALL, "robots.driver": "navigation", "mapping.enabled": True}


def test_the_mapping_topics_are_the_documented_ros_names():
    assert (SCANS, UPDATES, FLEET_MAP) == (
        "/fleet/mapping/scans",
        "/fleet/mapping/updates",
        "/fleet/map",
    )
    assert map_topic("robot_2") == "/robot_2/map"
    assert correction_topic("robot_2") == "/robot_2/tf"


def test_the_mapping_topics_are_valid_and_distinct():
    robots = [f"robot_{i}" for i in range(1, 6)]
    topics = [SCANS, UPDATES, FLEET_MAP]
    topics += [f(r) for r in robots for f in (map_topic, correction_topic)]
    assert len(set(topics)) == len(topics)
    for t in topics:
        assert dds_topic(t) == "rt" + t


def test_mapping_robots_advertise_their_maps_latched_and_their_corrections():
    advertised = assemble(cosim.load_scenario("warehouse-random", MAPPING)).run.bus.advertised()
    for robot in ("robot_1", "robot_2", "robot_3"):
        assert advertised[map_topic(robot)].message_type is OccupancyGrid
        assert advertised[map_topic(robot)].qos is TopicQos.LATCHED
        assert advertised[correction_topic(robot)].message_type is TFMessage
    assert advertised[FLEET_MAP].qos is TopicQos.LATCHED
    assert SCANS not in advertised and UPDATES not in advertised  # mapping.share = "none"


def test_each_sharing_mode_advertises_its_own_topic():
    for share, topic, kind in (("scans", SCANS, LocalizedScan), ("maps", UPDATES, MapUpdate)):
        scenario = cosim.load_scenario("warehouse-random", {**MAPPING, "mapping.share": share})
        advertised = assemble(scenario).run.bus.advertised()
        assert advertised[topic].message_type is kind
        assert ({SCANS, UPDATES} - {topic}).isdisjoint(advertised)

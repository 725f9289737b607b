"""The bus topics of what Unity scenes publish into a run."""

from __future__ import annotations

from hypothesis import given, settings
from hypothesis import strategies as st

import cosim
from adapters.unity.inbound import pose_topics
from adapters.unity.topics import POSE_PREFIX, pose_bus_topic
from cosim.core.bus import Advertisement, TopicQos
from cosim.core.messages import PoseStamped
from cosim.runner.assembly import assemble


def test_a_scenes_pose_topic_is_taken_under_unity_on_the_bus():
    assert POSE_PREFIX == "/unity"
    assert pose_bus_topic("/robot_1/pose") == "/unity/robot_1/pose"
    assert pose_bus_topic("/vicon/body_3") == "/unity/vicon/body_3"


def test_the_unity_pose_source_advertises_each_tracked_body_under_the_prefix():
    bodies = [["robot_1", "/robot_1/pose"], ["robot_2", "/tracked/two"]]
    scenario = cosim.load_scenario(
        "lab-room",
        {"mocap.source": "unity", "mocap.bodies": bodies},
    )
    advertised = assemble(scenario).run.bus.advertised()
    for _, body in bodies:
        assert advertised[pose_bus_topic(body)].message_type is PoseStamped
    # the endpoint finds them there, and lets scenes publish on the bodies' own topics
    assert pose_topics(advertised) == {body: pose_bus_topic(body) for _, body in bodies}


NAMES = st.lists(st.from_regex(r"[a-z][a-z0-9_]{0,8}", fullmatch=True), min_size=1, max_size=3).map(
    lambda parts: "/" + "/".join(parts)
)


@settings(max_examples=60, deadline=None)
@given(st.lists(NAMES, min_size=1, max_size=4, unique=True))
def test_every_bus_topic_leads_back_to_its_scenes_topic(bodies):
    advertised = {
        pose_bus_topic(b): Advertisement(pose_bus_topic(b), PoseStamped, TopicQos.DEFAULT)
        for b in bodies
    }
    assert pose_topics(advertised) == {b: pose_bus_topic(b) for b in bodies}
    assert len({pose_bus_topic(b) for b in bodies}) == len(bodies)

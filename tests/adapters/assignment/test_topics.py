import pytest

import cosim
from adapters.assignment.protocols import Cbba, DistributedSimplex
from adapters.assignment.topics import ASSIGNMENT, BASES, BIDS
from adapters.ros2dds.naming import dds_topic
from adapters.tasks import topics as tasks
from cosim.core.messages import CbbaBids, SimplexBasis, TaskAssignment
from cosim.runner.assembly import assemble
from tests.conftest import SMALL


def test_the_assignment_topics_are_the_documented_ros_names_on_the_fleet_namespace():
    assert (BASES, BIDS, ASSIGNMENT) == ("/fleet/dta/bases", "/fleet/dta/bids", "/fleet/assignment")
    for topic in (BASES, BIDS, ASSIGNMENT):
        assert dds_topic(topic) == "rt" + topic


def test_the_assignment_topics_are_distinct_from_each_other_and_the_task_sources():
    theirs = {tasks.TASKS, tasks.CLAIMS, tasks.SERVICE_REQUESTS, tasks.DONE, tasks.REPORTS}
    assert len({BASES, BIDS, ASSIGNMENT}) == 3
    assert theirs.isdisjoint({BASES, BIDS, ASSIGNMENT})


def test_the_protocols_exchange_their_messages_on_their_own_topics():
    assert (DistributedSimplex.topic, DistributedSimplex.message) == (BASES, SimplexBasis)
    assert (Cbba.topic, Cbba.message) == (BIDS, CbbaBids)


@pytest.mark.parametrize(
    ("protocol", "topic", "kind"),
    [("distributed_simplex", BASES, SimplexBasis), ("cbba", BIDS, CbbaBids)],
)
def test_a_run_advertises_the_chosen_protocols_topic_and_the_decisions(protocol, topic, kind):
    overrides = {**SMALL, "robots.driver": "tasks", "assignment.protocol": protocol}
    advertised = assemble(cosim.load_scenario("warehouse-random", overrides)).run.bus.advertised()
    assert advertised[topic].message_type is kind
    assert ({BASES, BIDS} - {topic}).isdisjoint(advertised)
    assert advertised[ASSIGNMENT].message_type is TaskAssignment

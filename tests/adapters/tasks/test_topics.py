"""Topics of the task source and the robots that serve its tasks."""

from __future__ import annotations

from adapters.tasks.topics import (
    CLAIMS,
    DONE,
    REPORTS,
    SERVICE_REQUESTS,
    TASKS,
    ack_topic,
    order_topic,
    reply_topic,
)


def test_the_fleets_topics_are_under_fleet():
    assert TASKS == "/fleet/tasks"
    assert CLAIMS == "/fleet/claims"
    assert SERVICE_REQUESTS == "/fleet/service/requests"
    assert DONE == "/fleet/tasks/done"
    assert REPORTS == "/fleet/robot_reports"


def test_answers_to_a_robot_are_in_its_own_namespace():
    assert reply_topic("robot_2") == "/robot_2/service/reply"
    assert ack_topic("robot_2") == "/robot_2/service/done_ack"
    assert order_topic("robot_2") == "/robot_2/task_order"


def test_no_two_topics_are_the_same():
    robots = [f"robot_{i}" for i in range(1, 6)]
    names = [TASKS, CLAIMS, SERVICE_REQUESTS, DONE, REPORTS]
    names += [f(r) for r in robots for f in (reply_topic, ack_topic, order_topic)]
    assert len(set(names)) == len(names) == 5 + 3 * len(robots)

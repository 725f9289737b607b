"""Topics of the task source on the base station and the robots that serve its tasks."""

from __future__ import annotations

from adapters.naming import topic

TASKS = "/fleet/tasks"
"""TaskSet broadcasts of the task source."""
CLAIMS = "/fleet/claims"
"""TaskClaim broadcasts of the robots (to the base and every robot)."""
SERVICE_REQUESTS = "/fleet/service/requests"
"""ServiceRequest from robots to the base."""
DONE = "/fleet/tasks/done"
"""TaskDone from robots to the base."""
REPORTS = "/fleet/robot_reports"
"""RobotState pose reports to the base (for a central solver)."""


def reply_topic(robot: str) -> str:
    """ServiceReply to ``robot``."""
    return topic(robot, "service/reply")


def ack_topic(robot: str) -> str:
    """TaskDone acknowledgements of the task source to ``robot``."""
    return topic(robot, "service/done_ack")


def order_topic(robot: str) -> str:
    """TaskOrder to ``robot`` (from a central solver on the base station)."""
    return topic(robot, "task_order")

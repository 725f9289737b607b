"""Topics of dynamic task assignment (robots and the base station)."""

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
"""RobotState pose reports to the base (centralized baseline)."""
BASES = "/fleet/dta/bases"
"""SimplexBasis broadcasts among robots (distributed simplex)."""
BIDS = "/fleet/dta/bids"
"""AuctionBids broadcasts among robots (CBBA)."""
ASSIGNMENT = "/fleet/assignment"
"""TaskAssignment: what each robot's protocol decided (for tools; nothing subscribes)."""


def reply_topic(robot: str) -> str:
    """ServiceReply to ``robot``."""
    return topic(robot, "service/reply")


def ack_topic(robot: str) -> str:
    """TaskDone acknowledgements of the task source to ``robot``."""
    return topic(robot, "service/done_ack")


def order_topic(robot: str) -> str:
    """TaskOrder to ``robot`` (centralized baseline)."""
    return topic(robot, "task_order")

"""Messages carried by the bus: immutable, typed, each mapped to a ROS 2 type.

Every message knows its ROS 2 type (for bag export and the DDS bridge) and its size in
bytes as ROS 2 would put it on the wire: the CDR encoding (XCDR1, little endian) of the
message plus the 4-byte encapsulation header (alignment counts from the end of that
header). The network model uses this size for
serialization delay and bandwidth, so sizes are computed from content, never guessed.

Frames follow REP 105: ``map`` (fixed world frame), ``odom`` (drifting, continuous),
``base_link`` (robot body), ``laser`` (sensor).
"""

from cosim.messages.base import Message
from cosim.messages.navigation import NavGoal, NavStatus, RobotState
from cosim.messages.ros import Goal, LaserScan, Odometry, PoseStamped, Twist
from cosim.messages.tasks import (
    AuctionBids,
    ServiceReply,
    ServiceRequest,
    SimplexBasis,
    TaskClaim,
    TaskDone,
    TaskInfo,
    TaskOrder,
    TaskSet,
)

__all__ = [
    "AuctionBids",
    "Goal",
    "LaserScan",
    "Message",
    "NavGoal",
    "NavStatus",
    "Odometry",
    "PoseStamped",
    "RobotState",
    "ServiceReply",
    "ServiceRequest",
    "SimplexBasis",
    "TaskClaim",
    "TaskDone",
    "TaskInfo",
    "TaskOrder",
    "TaskSet",
    "Twist",
]

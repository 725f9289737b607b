"""Messages carried by the bus: immutable, typed, each mapped to a ROS 2 type.

Every message knows its ROS 2 type (for bag export and the DDS bridge) and its size in
bytes as ROS 2 would put it on the wire: the CDR encoding (XCDR1, little endian) of the
message plus the 4-byte encapsulation header (alignment counts from the end of that
header). The network model uses this size for
serialization delay and bandwidth, so sizes are computed from content, never guessed.

Frames follow REP 105: ``map`` (fixed world frame), ``odom`` (drifting, continuous),
``base_link`` (robot body), ``laser`` (sensor).
"""

from cosim.core.messages.assignment import AuctionBids, SimplexBasis, TaskAssignment, TaskOrder
from cosim.core.messages.base import Message
from cosim.core.messages.frames import Clock, TFMessage, Transform
from cosim.core.messages.mapping import LocalizedScan, MapUpdate
from cosim.core.messages.navigation import NavGoal, NavStatus, RobotState
from cosim.core.messages.ros import Goal, LaserScan, Odometry, Path, PoseStamped, Twist
from cosim.core.messages.scene import Marker, MarkerAction, MarkerArray, MarkerType, OccupancyGrid
from cosim.core.messages.tasks import (
    ServiceReply,
    ServiceRequest,
    TaskClaim,
    TaskDone,
    TaskInfo,
    TaskSet,
)

__all__ = [
    "AuctionBids",
    "Clock",
    "Goal",
    "LaserScan",
    "LocalizedScan",
    "MapUpdate",
    "Marker",
    "MarkerAction",
    "MarkerArray",
    "MarkerType",
    "Message",
    "NavGoal",
    "NavStatus",
    "OccupancyGrid",
    "Odometry",
    "Path",
    "PoseStamped",
    "RobotState",
    "ServiceReply",
    "ServiceRequest",
    "SimplexBasis",
    "TFMessage",
    "TaskAssignment",
    "TaskClaim",
    "TaskDone",
    "TaskInfo",
    "TaskOrder",
    "TaskSet",
    "Transform",
    "Twist",
]

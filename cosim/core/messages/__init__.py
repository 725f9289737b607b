"""Messages carried by the bus: immutable, typed, each declared once.

A message class is a frozen dataclass declared with :func:`ros_message`: from its typed
fields (or, for a view of one of ROS 2's standard types, its bindings onto that type)
come its ROS 2 type and ``.msg`` text (for bags and tools), its size in bytes as ROS 2
puts it on the wire, its CDR encoding and decoding, and its DDS type. The network model
uses the size for serialization delay and bandwidth, so sizes are computed from content,
never guessed.

Frames follow REP 105: ``map`` (fixed world frame), ``odom`` (drifting, continuous),
``base_link`` (robot body), ``laser`` (sensor).
"""

from cosim.core.messages.aliases import (
    Bytes,
    Duration,
    Float32s,
    Float64s,
    FrameId,
    Header,
    Int32s,
    Strings,
    Time,
    bool_,
    float32,
    float64,
    int8,
    int16,
    int32,
    int64,
    string,
    uint8,
    uint16,
    uint32,
    uint64,
)
from cosim.core.messages.assignment import CbbaBids, SimplexBasis, TaskAssignment, TaskOrder
from cosim.core.messages.declare import Message, ros_message
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
from cosim.core.messages.tf import Clock, TFMessage, Transform
from cosim.core.messages.views import Const, Each, Outer, Planar, Rows

__all__ = [
    "Bytes",
    "CbbaBids",
    "Clock",
    "Const",
    "Duration",
    "Each",
    "Float32s",
    "Float64s",
    "FrameId",
    "Goal",
    "Header",
    "Int32s",
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
    "Outer",
    "Path",
    "Planar",
    "PoseStamped",
    "RobotState",
    "Rows",
    "ServiceReply",
    "ServiceRequest",
    "SimplexBasis",
    "Strings",
    "TFMessage",
    "TaskAssignment",
    "TaskClaim",
    "TaskDone",
    "TaskInfo",
    "TaskOrder",
    "TaskSet",
    "Time",
    "Transform",
    "Twist",
    "bool_",
    "float32",
    "float64",
    "int8",
    "int16",
    "int32",
    "int64",
    "ros_message",
    "string",
    "uint8",
    "uint16",
    "uint32",
    "uint64",
]

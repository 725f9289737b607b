"""ROS 2 ``.msg`` definitions of the project's own types (``cosim_msgs``).

They let tools that know no cosim (rosbags, ``ros2 bag``, Foxglove) decode recorded
messages, and they are the layout the ``size_bytes`` of each message follows (the tests
serialize with rosbags against them).
"""

from __future__ import annotations

DEFINITIONS: dict[str, str] = {
    "cosim_msgs/msg/NavGoal": """
std_msgs/Header header
uint32 goal_id
float64 x
float64 y
float64 yaw
""",
    "cosim_msgs/msg/NavStatus": """
std_msgs/Header header
uint32 goal_id
string state
float64 x
float64 y
float64 remaining
""",
    "cosim_msgs/msg/RobotState": """
std_msgs/Header header
string robot
float64 x
float64 y
float64 yaw
float64 v
float64 radius
""",
    "cosim_msgs/msg/TaskInfo": """
uint32 task_id
float64 x
float64 y
string[] eligible
string holder
""",
    "cosim_msgs/msg/TaskSet": """
std_msgs/Header header
uint32 epoch
cosim_msgs/TaskInfo[] tasks
""",
    "cosim_msgs/msg/TaskClaim": """
std_msgs/Header header
uint32 epoch
uint32 task_id
string robot
float64 cost
string state
""",
    "cosim_msgs/msg/ServiceRequest": """
std_msgs/Header header
uint32 task_id
string robot
""",
    "cosim_msgs/msg/ServiceReply": """
std_msgs/Header header
uint32 task_id
string robot
bool granted
""",
    "cosim_msgs/msg/TaskDone": """
std_msgs/Header header
uint32 task_id
string robot
""",
    "cosim_msgs/msg/SimplexColumn": """
uint8 kind
int32 robot
int32 task
float64 cost
""",
    "cosim_msgs/msg/SimplexBasis": """
std_msgs/Header header
uint32 epoch
string robot
uint32 round
cosim_msgs/SimplexColumn[] columns
""",
    "cosim_msgs/msg/AuctionBids": """
std_msgs/Header header
uint32 epoch
string robot
float64[] bids
int32[] winners
""",
    "cosim_msgs/msg/TaskOrder": """
std_msgs/Header header
uint32 epoch
string robot
int32 task_id
float64 cost
""",
    "cosim_msgs/msg/LocalizedScan": """
std_msgs/Header header
string robot
float64 x
float64 y
float64 yaw
float32 angle_min
float32 angle_increment
float32 range_min
float32 range_max
float32[] ranges
""",
    "cosim_msgs/msg/MapUpdate": """
std_msgs/Header header
string robot
uint32 seq
int32 ix0
int32 iy0
uint32 width
uint32 height
float32 scale
string encoding
uint8[] data
""",
    "cosim_msgs/msg/TaskAssignment": """
std_msgs/Header header
uint32 epoch
string robot
int32 task_id
float64 cost
uint32 rounds
""",
}
"""``.msg`` text by ROS 2 type name."""

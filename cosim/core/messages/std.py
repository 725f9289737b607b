"""ROS 2's standard message types, declared once (their Humble definitions).

Jazzy's differ only in ``sensor_msgs/msg/Range``, which appends ``variance``.

The bus, the bags and DDS share these declarations: a bus message of a standard type binds
its fields onto one of them (:func:`cosim.core.messages.declare.message`'s ``wire``), a bag
embeds their ``.msg`` text, and DDS types are made from them. The tests check every one
field for field against rosbags' ROS 2 type store.
"""

from __future__ import annotations

from cosim.core.messages.wire import (
    BOOL,
    FLOAT32,
    FLOAT64,
    INT8,
    INT32,
    STRING,
    UINT8,
    UINT32,
    Array,
    Sequence,
    struct,
)

TIME = struct("builtin_interfaces/msg/Time", nanoseconds=True, sec=INT32, nanosec=UINT32)
"""An instant: seconds and nanoseconds (values: integer ns)."""
DURATION = struct("builtin_interfaces/msg/Duration", nanoseconds=True, sec=INT32, nanosec=UINT32)
"""A span of time (values: integer ns)."""
HEADER = struct("std_msgs/msg/Header", stamp=TIME, frame_id=STRING)
"""The instant a message describes and the frame it is expressed in."""
COLOR = struct("std_msgs/msg/ColorRGBA", r=FLOAT32, g=FLOAT32, b=FLOAT32, a=FLOAT32)

POINT = struct("geometry_msgs/msg/Point", x=FLOAT64, y=FLOAT64, z=FLOAT64)
QUATERNION = struct(
    "geometry_msgs/msg/Quaternion", defaults={"w": 1.0}, x=FLOAT64, y=FLOAT64, z=FLOAT64, w=FLOAT64
)
POSE = struct("geometry_msgs/msg/Pose", position=POINT, orientation=QUATERNION)
POSE_STAMPED = struct("geometry_msgs/msg/PoseStamped", header=HEADER, pose=POSE)
POSE_WITH_COVARIANCE = struct(
    "geometry_msgs/msg/PoseWithCovariance", pose=POSE, covariance=Array(FLOAT64, 36)
)
POSE_WITH_COVARIANCE_STAMPED = struct(
    "geometry_msgs/msg/PoseWithCovarianceStamped", header=HEADER, pose=POSE_WITH_COVARIANCE
)
VECTOR3 = struct("geometry_msgs/msg/Vector3", x=FLOAT64, y=FLOAT64, z=FLOAT64)
TWIST = struct("geometry_msgs/msg/Twist", linear=VECTOR3, angular=VECTOR3)
TWIST_STAMPED = struct("geometry_msgs/msg/TwistStamped", header=HEADER, twist=TWIST)
TWIST_WITH_COVARIANCE = struct(
    "geometry_msgs/msg/TwistWithCovariance", twist=TWIST, covariance=Array(FLOAT64, 36)
)
TRANSFORM = struct("geometry_msgs/msg/Transform", translation=VECTOR3, rotation=QUATERNION)
TRANSFORM_STAMPED = struct(
    "geometry_msgs/msg/TransformStamped", header=HEADER, child_frame_id=STRING, transform=TRANSFORM
)

ODOMETRY = struct(
    "nav_msgs/msg/Odometry",
    header=HEADER,
    child_frame_id=STRING,
    pose=POSE_WITH_COVARIANCE,
    twist=TWIST_WITH_COVARIANCE,
)
PATH = struct("nav_msgs/msg/Path", header=HEADER, poses=Sequence(POSE_STAMPED))
MAP_META_DATA = struct(
    "nav_msgs/msg/MapMetaData",
    map_load_time=TIME,
    resolution=FLOAT32,
    width=UINT32,
    height=UINT32,
    origin=POSE,
)
OCCUPANCY_GRID = struct(
    "nav_msgs/msg/OccupancyGrid", header=HEADER, info=MAP_META_DATA, data=Sequence(INT8)
)

LASER_SCAN = struct(
    "sensor_msgs/msg/LaserScan",
    header=HEADER,
    angle_min=FLOAT32,
    angle_max=FLOAT32,
    angle_increment=FLOAT32,
    time_increment=FLOAT32,
    scan_time=FLOAT32,
    range_min=FLOAT32,
    range_max=FLOAT32,
    ranges=Sequence(FLOAT32),
    intensities=Sequence(FLOAT32),
)
RANGE = struct(
    "sensor_msgs/msg/Range",
    header=HEADER,
    radiation_type=UINT8,
    field_of_view=FLOAT32,
    min_range=FLOAT32,
    max_range=FLOAT32,
    range=FLOAT32,
)
BATTERY_STATE = struct(
    "sensor_msgs/msg/BatteryState",
    header=HEADER,
    voltage=FLOAT32,
    temperature=FLOAT32,
    current=FLOAT32,
    charge=FLOAT32,
    capacity=FLOAT32,
    design_capacity=FLOAT32,
    percentage=FLOAT32,
    power_supply_status=UINT8,
    power_supply_health=UINT8,
    power_supply_technology=UINT8,
    present=BOOL,
    cell_voltage=Sequence(FLOAT32),
    cell_temperature=Sequence(FLOAT32),
    location=STRING,
    serial_number=STRING,
)
COMPRESSED_IMAGE = struct(
    "sensor_msgs/msg/CompressedImage", header=HEADER, format=STRING, data=Sequence(UINT8)
)

TF_MESSAGE = struct("tf2_msgs/msg/TFMessage", transforms=Sequence(TRANSFORM_STAMPED))
CLOCK = struct("rosgraph_msgs/msg/Clock", clock=TIME)

UV_COORDINATE = struct("visualization_msgs/msg/UVCoordinate", u=FLOAT32, v=FLOAT32)
MESH_FILE = struct("visualization_msgs/msg/MeshFile", filename=STRING, data=Sequence(UINT8))
MARKER = struct(
    "visualization_msgs/msg/Marker",
    header=HEADER,
    ns=STRING,
    id=INT32,
    type=INT32,
    action=INT32,
    pose=POSE,
    scale=VECTOR3,
    color=COLOR,
    lifetime=DURATION,
    frame_locked=BOOL,
    points=Sequence(POINT),
    colors=Sequence(COLOR),
    texture_resource=STRING,
    texture=COMPRESSED_IMAGE,
    uv_coordinates=Sequence(UV_COORDINATE),
    text=STRING,
    mesh_resource=STRING,
    mesh_file=MESH_FILE,
    mesh_use_embedded_materials=BOOL,
)
MARKER_ARRAY = struct("visualization_msgs/msg/MarkerArray", markers=Sequence(MARKER))

STANDARD = (
    TIME,
    DURATION,
    HEADER,
    COLOR,
    POINT,
    QUATERNION,
    POSE,
    POSE_STAMPED,
    POSE_WITH_COVARIANCE,
    POSE_WITH_COVARIANCE_STAMPED,
    VECTOR3,
    TWIST,
    TWIST_STAMPED,
    TWIST_WITH_COVARIANCE,
    TRANSFORM,
    TRANSFORM_STAMPED,
    ODOMETRY,
    PATH,
    MAP_META_DATA,
    OCCUPANCY_GRID,
    LASER_SCAN,
    RANGE,
    BATTERY_STATE,
    COMPRESSED_IMAGE,
    TF_MESSAGE,
    CLOCK,
    UV_COORDINATE,
    MESH_FILE,
    MARKER,
    MARKER_ARRAY,
)
"""Every standard type declared here."""

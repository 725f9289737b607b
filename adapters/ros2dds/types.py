"""ROS 2 messages as Cyclone DDS types, made from their one declaration.

Each type is a ``@final`` IDL struct named as ``rmw_cyclonedds`` names the ROS type
(``pkg::msg::dds_::Name_``, see :mod:`adapters.ros2dds.naming`), with the fields of its
declaration (:mod:`cosim.core.messages.std` for ROS 2's standard types, a message class's
``wire`` for cosim's and a plugin's) in order; final structs are serialized as plain CDR
(XCDR1), which is what ROS 2 sends, so a sample is byte-equal to the message's own
``to_cdr()`` and to rosbags' ``serialize_cdr``. A bus message goes out as
``dds_type(Message.wire).deserialize(message.to_cdr())`` and a sample comes in as
``Message.from_cdr(sample.serialize())``. Units and frames are ROS's (REP 103): metres,
radians, seconds; ``header.frame_id`` names the frame a message is expressed in.
"""

# No ``from __future__ import annotations``: cyclonedds resolves string annotations by
# splitting them at dots (``idl.float64`` as a module ``idl``), so they must be evaluated.
import dataclasses
import math
from collections.abc import Sequence
from functools import cache
from typing import Annotated, Any

from cyclonedds.idl import IdlStruct
from cyclonedds.idl import types as idl
from cyclonedds.idl.annotations import final

from adapters.ros2dds.naming import dds_type as dds_type_name
from cosim.core.messages import std
from cosim.core.messages.wire import Array, Primitive, Struct, Text, WireType
from cosim.core.messages.wire import Sequence as WireSequence
from models.geometry.se2 import yaw_of_quaternion

_NS_PER_S = 1_000_000_000
_INT32 = 2**31
_IDL = {
    "bool": bool,
    "byte": idl.uint8,
    "char": idl.uint8,
    "int8": idl.int8,
    "uint8": idl.uint8,
    "int16": idl.int16,
    "uint16": idl.uint16,
    "int32": idl.int32,
    "uint32": idl.uint32,
    "int64": idl.int64,
    "uint64": idl.uint64,
    "float32": idl.float32,
    "float64": idl.float64,
}


@cache
def dds_type(kind: Struct) -> type[IdlStruct]:
    """The Cyclone DDS type of a declared ROS 2 message type (made once per type).

    Every field has the zero of its type (or its ``.msg`` default) as default, so a sample
    may be built with keywords for what matters.
    """
    meta: Any = type(IdlStruct)  # cyclonedds's IdlMeta
    name = kind.ros_type.rsplit("/", 1)[1]
    namespace: Any = meta.__prepare__(name, (IdlStruct,), typename=dds_type_name(kind.ros_type))
    defaults = dict(kind.defaults)
    for name, field_kind in kind.fields:
        namespace["__annotations__"][name] = _idl(field_kind)
        namespace[name] = _default(field_kind, defaults.get(name))
    made: Any = meta(name, (IdlStruct,), namespace)
    made.__doc__ = f"{kind.ros_type}, as DDS carries it (from its declaration)."
    return final(dataclasses.dataclass(made))  # type: ignore[no-any-return]


def _idl(kind: WireType) -> Any:
    """The cyclonedds annotation of a field's type."""
    if isinstance(kind, Primitive):
        return _IDL[kind.name]
    if isinstance(kind, Text):
        return str
    if isinstance(kind, Struct):
        return dds_type(kind)
    element = _idl(kind.element)
    if isinstance(kind, Array):
        return Annotated[Sequence[element], idl.array(element, kind.length)]  # type: ignore[valid-type]
    assert isinstance(kind, WireSequence)
    return Annotated[Sequence[element], idl.sequence(element)]  # type: ignore[valid-type]


def _default(kind: WireType, given: Any) -> Any:
    """A field's default: ``given``, or the zero of its type."""
    if given is not None:
        return given
    if isinstance(kind, Primitive):
        return kind.zero
    if isinstance(kind, Text):
        return ""
    if isinstance(kind, Struct):
        return dataclasses.field(default_factory=dds_type(kind))
    if isinstance(kind, Array):
        zero = kind.element.zero if isinstance(kind.element, Primitive | Text) else None
        return dataclasses.field(default_factory=lambda: [zero] * kind.length)
    return dataclasses.field(default_factory=list)


Time: Any = dds_type(std.TIME)
Header: Any = dds_type(std.HEADER)
Point: Any = dds_type(std.POINT)
Quaternion: Any = dds_type(std.QUATERNION)
Pose: Any = dds_type(std.POSE)
PoseStamped: Any = dds_type(std.POSE_STAMPED)
PoseWithCovariance: Any = dds_type(std.POSE_WITH_COVARIANCE)
PoseWithCovarianceStamped: Any = dds_type(std.POSE_WITH_COVARIANCE_STAMPED)
Vector3: Any = dds_type(std.VECTOR3)
Twist: Any = dds_type(std.TWIST)
TwistWithCovariance: Any = dds_type(std.TWIST_WITH_COVARIANCE)
Transform: Any = dds_type(std.TRANSFORM)
TransformStamped: Any = dds_type(std.TRANSFORM_STAMPED)
Odometry: Any = dds_type(std.ODOMETRY)
LaserScan: Any = dds_type(std.LASER_SCAN)
"""The standard types a physical robot's bridge and stand-in exchange, by their ROS names."""


def yaw_to_quaternion(yaw: float) -> tuple[float, float, float, float]:
    """The quaternion ``(x, y, z, w)`` of a rotation by ``yaw`` (rad) about z."""
    return (0.0, 0.0, math.sin(0.5 * yaw), math.cos(0.5 * yaw))


quaternion_to_yaw = yaw_of_quaternion
"""The yaw (rad, in [-pi, pi]) of a quaternion ``(x, y, z, w)``, as tf2 computes it."""

QUATERNION_NORM_TOLERANCE = 0.05
"""How far from 1 a received quaternion's norm may be before the sample is refused."""


def planar_pose(header: Any, pose: Any) -> tuple[int, float, float, float] | None:
    """(stamp ns, x_m, y_m, yaw_rad) of a received pose, or None if it is not a pose.

    Received samples are untrusted: any non-finite value, or a quaternion whose norm is
    off 1 by more than :data:`QUATERNION_NORM_TOLERANCE`, and the sample is refused.
    """
    p, q = pose.position, pose.orientation
    if not all(math.isfinite(v) for v in (p.x, p.y, p.z, q.x, q.y, q.z, q.w)):
        return None
    norm = math.sqrt(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w)
    if abs(norm - 1.0) > QUATERNION_NORM_TOLERANCE:
        return None
    return stamp_ns(header.stamp), p.x, p.y, quaternion_to_yaw(q.x, q.y, q.z, q.w)


def stamp(ns: int) -> Any:
    """A ROS time from integer nanoseconds (``nanosec`` is always in [0, 1e9)).

    Raises:
        ValueError: the seconds do not fit ROS's int32.
    """
    sec, nanosec = divmod(ns, _NS_PER_S)
    if not -_INT32 <= sec < _INT32:
        raise ValueError(f"time {ns} ns is out of ROS's range; expected |seconds| < 2^31")
    return Time(sec=sec, nanosec=nanosec)


def stamp_ns(time: Any) -> int:
    """Integer nanoseconds of a ROS time."""
    return int(time.sec) * _NS_PER_S + int(time.nanosec)

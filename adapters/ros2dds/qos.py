"""ROS 2's QoS profiles as Cyclone DDS QoS.

The values are those of ``rmw/include/rmw/qos_profiles.h`` (ros2/rmw), which
``rmw_cyclonedds`` turns into DDS policies one for one:

- ``rmw_qos_profile_sensor_data``: best effort, keep last 5, volatile;
- ``rmw_qos_profile_default``: reliable, keep last 10, volatile.

A reader and a writer match if the writer offers at least the reliability the reader
asks for, so a best-effort reader receives from a reliable writer but not the reverse.
Data representation is pinned to XCDR1 (plain CDR), the only one ROS 2 speaks.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from enum import Enum
from types import MappingProxyType

from cyclonedds.qos import Policy, Qos
from cyclonedds.util import duration

SENSOR_DATA_DEPTH = 5
"""History depth of ``rmw_qos_profile_sensor_data``."""
DEFAULT_DEPTH = 10
"""History depth of ``rmw_qos_profile_default``."""
MAX_BLOCKING_S = 0.1
"""How long a reliable write may block on a full writer history (s).

``max_blocking_time`` is local to the writer and not part of matching; ``rmw_cyclonedds``
uses infinity, but a wall-clock loop must never stall on a slow reader.
"""


class QosKind(Enum):
    """The ROS 2 QoS profile a publisher or subscription uses."""

    SENSOR_DATA = "sensor_data"
    """``rmw_qos_profile_sensor_data``: poses, odometry, scans."""
    DEFAULT = "default"
    """``rmw_qos_profile_default``: commands such as ``cmd_vel``."""


def sensor_data_qos() -> Qos:
    """``rmw_qos_profile_sensor_data``: best effort, keep last 5, volatile."""
    return Qos(
        Policy.Reliability.BestEffort,
        Policy.History.KeepLast(depth=SENSOR_DATA_DEPTH),
        Policy.Durability.Volatile,
        Policy.DataRepresentation(use_cdrv0_representation=True),
    )


def default_qos() -> Qos:
    """``rmw_qos_profile_default``: reliable, keep last 10, volatile."""
    return Qos(
        Policy.Reliability.Reliable(max_blocking_time=duration(seconds=MAX_BLOCKING_S)),
        Policy.History.KeepLast(depth=DEFAULT_DEPTH),
        Policy.Durability.Volatile,
        Policy.DataRepresentation(use_cdrv0_representation=True),
    )


_PROFILES: Mapping[QosKind, Callable[[], Qos]] = MappingProxyType(
    {QosKind.SENSOR_DATA: sensor_data_qos, QosKind.DEFAULT: default_qos}
)


def qos_for(kind: QosKind) -> Qos:
    """The Cyclone DDS QoS of a ROS 2 profile."""
    return _PROFILES[kind]()

"""Message schemas and QoS as rosbag2 records them, for the bag and the live view alike.

A channel of a recording is a topic with its ROS 2 type, the type's ``.msg`` definition
with every nested definition appended as rosbag2 embeds it (``ros2msg``), the type's
RIHS01 hash, and the QoS the topic is offered with. Standard types come from rosbags'
ROS 2 Humble type store; the project's own (``cosim_msgs``) and a plugin's from their
declarations (each message class's ``wire`` type and the types it nests), so any tool
decodes every recorded message.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from functools import lru_cache

from rosbags.interfaces import (
    Qos,
    QosDurability,
    QosHistory,
    QosLiveliness,
    QosReliability,
    QosTime,
)
from rosbags.typesys import Stores, get_types_from_msg, get_typestore
from rosbags.typesys.store import Typestore

from cosim.core.bus import Advertisement, TopicQos
from cosim.core.messages.wire import Struct

INFINITE = QosTime(2_147_483_647, 4_294_967_295)
"""An unset deadline, lifespan or lease as Humble's rosbag2 writes it (v8 metadata)."""


@dataclass(frozen=True, slots=True)
class ChannelSpec:
    """A recorded topic.

    Attributes:
        topic: topic name.
        msgtype: ROS 2 type, ``pkg/msg/Type``.
        msgdef: the ``.msg`` definition with its dependencies (rosbag2's ``ros2msg``).
        rihs01: the type's hash (``RIHS01_...``).
        qos: how the topic is offered.
    """

    topic: str
    msgtype: str
    msgdef: str
    rihs01: str
    qos: TopicQos


@lru_cache(maxsize=1)
def typestore() -> Typestore:
    """ROS 2 Humble's standard types (built once per process; declared types join it)."""
    return get_typestore(Stores.ROS2_HUMBLE)


def register(kind: Struct) -> None:
    """Make a declared type, and every type it nests, known to the type store.

    Standard types are there already; a type of cosim's or a plugin's is registered from
    its ``.msg`` text.
    """
    store = typestore()
    for nested in [*kind.dependencies(), kind]:
        if nested.ros_type not in store.fielddefs:
            store.register(get_types_from_msg(nested.msg_text(), nested.ros_type))


@lru_cache(maxsize=256)
def definition(msgtype: str) -> tuple[str, str]:
    """The (``ros2msg`` definition, RIHS01 hash) of a ROS 2 type."""
    store = typestore()
    text, _ = store.generate_msgdef(msgtype, ros_version=2)
    return text, store.hash_rihs01(msgtype)


def channel_specs(topics: Mapping[str, Advertisement]) -> list[ChannelSpec]:
    """The channels of the given advertised topics, in their order."""
    specs = []
    for topic, ad in topics.items():
        msgtype = ad.message_type.ros_type
        register(ad.message_type.wire)
        text, digest = definition(msgtype)
        specs.append(ChannelSpec(topic, msgtype, text, digest, ad.qos))
    return specs


def recorded_qos(qos: TopicQos) -> list[Qos]:
    """The offered QoS a bag records for a topic: the latched profile, or none.

    A latched topic must be replayed transient-local, or a subscriber that starts after
    ``ros2 bag play`` never gets the map. For every other topic the bag records no profile
    and ``ros2 bag play`` publishes with its default (reliable, volatile, keep last 10),
    which every subscriber matches, best-effort ones included; a replayed best-effort
    publisher would not reach a reliable subscriber. Writing no profile also keeps a
    300-topic bag's metadata (one YAML document per profile) from taking 0.4 s to write.
    """
    return [offered_qos(qos)] if qos is TopicQos.LATCHED else []


def offered_qos(qos: TopicQos) -> Qos:
    """The QoS profile rclcpp offers for such a topic, as rosbag2 records it."""
    reliable = QosReliability.BEST_EFFORT if qos is TopicQos.SENSOR else QosReliability.RELIABLE
    durable = QosDurability.TRANSIENT_LOCAL if qos is TopicQos.LATCHED else QosDurability.VOLATILE
    depth = {TopicQos.DEFAULT: 10, TopicQos.SENSOR: 5, TopicQos.LATCHED: 1}[qos]
    return Qos(
        history=QosHistory.KEEP_LAST,
        depth=depth,
        reliability=reliable,
        durability=durable,
        deadline=INFINITE,
        lifespan=INFINITE,
        liveliness=QosLiveliness.AUTOMATIC,
        liveliness_lease_duration=INFINITE,
        avoid_ros_namespace_conventions=False,
    )

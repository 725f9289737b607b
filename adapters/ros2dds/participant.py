"""A DDS participant that speaks ROS 2: publishers and subscriptions on ROS 2 topics.

By default the participant talks over loopback only (unicast discovery to 127.0.0.1, no
multicast), which is enough for processes on one machine and never leaks onto a
network; given an interface it uses that interface with multicast discovery, as Cyclone
DDS (and so ``rmw_cyclonedds``) does by default. Received samples are CDR bytes decoded
into the fixed IDL structs of :mod:`adapters.ros2dds.types`: nothing received is unpickled
or evaluated, and a sample that does not decode is counted and dropped.
"""

from __future__ import annotations

import ipaddress
import socket
import threading
from collections.abc import Sequence
from dataclasses import dataclass
from types import TracebackType
from typing import Any, Generic, TypeVar
from xml.sax.saxutils import quoteattr

from cyclonedds.builtin import BuiltinDataReader, BuiltinTopicDcpsPublication
from cyclonedds.core import DDSException, InstanceState, ReadCondition, SampleState, ViewState
from cyclonedds.domain import Domain, DomainParticipant
from cyclonedds.idl import IdlStruct
from cyclonedds.pub import DataWriter
from cyclonedds.sub import DataReader
from cyclonedds.topic import Topic

from adapters.ros2dds.naming import dds_topic, dds_type
from adapters.ros2dds.qos import QosKind, qos_for
from cosim.core.errors import BridgeError

T = TypeVar("T", bound=IdlStruct)

MAX_DOMAIN = 232
"""Largest DDS domain id with the standard port mapping (7400 + 250 x domain < 65536)."""
LOOPBACK_CONFIG = (
    '<CycloneDDS><Domain id="any"><General><Interfaces>'
    '<NetworkInterface address="127.0.0.1"/></Interfaces>'
    "<AllowMulticast>false</AllowMulticast></General>"
    '<Discovery><Peers><Peer address="127.0.0.1"/></Peers></Discovery></Domain></CycloneDDS>'
)
"""Cyclone DDS configuration for loopback only: ``lo`` has no multicast, so discovery is
unicast to the peer 127.0.0.1 (ports of participant indices 0-9 by default)."""
_TAKE_LIMIT = 256
_ENDPOINT_LIMIT = 4096


def interface_config(interface: str) -> str:
    """Cyclone DDS configuration for one network interface, multicast as Cyclone's default.

    Args:
        interface: an interface name (``eth0``) or one of its addresses (``192.168.1.10``).

    Returns:
        The XML configuration.
    """
    try:
        ipaddress.ip_address(interface)
    except ValueError:
        selector = f"name={quoteattr(interface)}"
    else:
        selector = f"address={quoteattr(interface)}"
    return (
        '<CycloneDDS><Domain id="any"><General><Interfaces>'
        f"<NetworkInterface {selector}/></Interfaces></General></Domain></CycloneDDS>"
    )


class _ConfiguredDomain(Domain):
    """A Cyclone DDS domain that remembers the configuration it was created with."""

    def __init__(self, domain_id: int, config: str) -> None:
        super().__init__(domain_id, config)
        self.config = config


@dataclass(frozen=True)
class _Network:
    """Where a participant talks: Cyclone's configuration and words for messages."""

    config: str
    where: str
    expected: str


def _network(interface: str | None) -> _Network:
    if interface is None:
        return _Network(LOOPBACK_CONFIG, "loopback", "loopback (127.0.0.1) to be up")
    try:
        ipaddress.ip_address(interface)
    except ValueError:
        names = sorted(name for _, name in socket.if_nameindex())
        if interface not in names:
            raise BridgeError(
                f"network interface {interface!r} does not exist; expected an interface"
                f" address or one of {', '.join(names)}"
            ) from None
    return _Network(
        interface_config(interface),
        f"interface {interface!r}",
        "the name or address of an interface of this machine that is up",
    )


class _Discovery:
    """Writers that discovery has found, read from Cyclone's builtin publication topic."""

    def __init__(self, participant: DomainParticipant) -> None:
        self.own = participant.guid
        """The participant's own GUID, as ``participant_key`` of its writers."""
        self._reader = BuiltinDataReader(participant, BuiltinTopicDcpsPublication)
        any_state = SampleState.Any | ViewState.Any
        self._alive = ReadCondition(self._reader, any_state | InstanceState.Alive)
        self._gone = ReadCondition(
            self._reader,
            any_state | InstanceState.NotAliveDisposed | InstanceState.NotAliveNoWriters,
        )

    def writers(self) -> list[Any]:
        """The ``DcpsEndpoint`` of every writer alive now (non-blocking)."""
        self._reader.take(N=_ENDPOINT_LIMIT, condition=self._gone)  # forget those gone
        alive: list[Any] = self._reader.read(N=_ENDPOINT_LIMIT, condition=self._alive)
        return alive


_DOMAINS = threading.Lock()
"""Cyclone's domains are process-wide: creating or joining one, and dropping the last
reference to one, must not interleave between threads."""


def _cyclone(exc: DDSException) -> str:
    """The name of Cyclone's return code, e.g. ``DDS_RETCODE_ERROR``."""
    name: str = DDSException.error_message_mapping.get(exc.code, (f"code {exc.code}",))[0]
    return name


def _join(domain: int, network: _Network) -> tuple[_ConfiguredDomain, DomainParticipant]:
    """Create the domain for ``network``, or join it if this process has it so configured.

    Returns:
        The domain, referenced by each of its participants so that it goes with the last
        one, and a new participant in it.
    """
    shared: _ConfiguredDomain | None = None
    try:
        shared = _ConfiguredDomain(domain, network.config)
    except DDSException as exc:
        if exc.code != DDSException.DDS_RETCODE_PRECONDITION_NOT_MET:  # not "exists already"
            raise BridgeError(
                f"cannot open DDS domain {domain} on {network.where} ({_cyclone(exc)});"
                f" expected {network.expected}"
            ) from exc
    try:
        participant = DomainParticipant(domain)
    except DDSException as exc:
        raise BridgeError(
            f"cannot join DDS domain {domain} on {network.where} ({_cyclone(exc)});"
            f" expected {network.expected}"
        ) from exc
    if shared is None:
        parent = participant.get_parent()
        if not isinstance(parent, _ConfiguredDomain) or parent.config != network.config:
            del participant, parent  # now, not when the traceback goes
            raise BridgeError(
                f"DDS domain {domain} is already open in this process with another"
                f" network configuration; expected {network.where} for every participant"
            )
        shared = parent
    return shared, participant


class Publisher(Generic[T]):
    """Writes samples of one IDL type on one ROS 2 topic."""

    def __init__(self, ros_topic: str, writer: DataWriter[T]) -> None:
        self.ros_topic = ros_topic
        self._writer: DataWriter[T] | None = writer
        self.published = 0
        """Samples written so far."""

    def publish(self, sample: T) -> None:
        """Write ``sample`` (never blocks longer than :data:`adapters.ros2dds.qos.MAX_BLOCKING_S`).

        Raises:
            BridgeError: the participant is closed or Cyclone DDS refuses the sample.
        """
        if self._writer is None:
            raise BridgeError(f"publisher on {self.ros_topic} is closed; expected an open one")
        try:
            self._writer.write(sample)
        except DDSException as exc:
            raise BridgeError(f"cannot publish on {self.ros_topic} ({_cyclone(exc)})") from exc
        self.published += 1

    def _close(self) -> None:
        self._writer = None


class Subscription(Generic[T]):
    """Receives samples of one IDL type on one ROS 2 topic, without ever blocking."""

    def __init__(self, ros_topic: str, idl_type: type[T], reader: DataReader[T]) -> None:
        self.ros_topic = ros_topic
        self._idl_type = idl_type
        self._reader: DataReader[T] | None = reader
        self.received = 0
        """Samples decoded and returned so far."""
        self.malformed = 0
        """Samples that arrived but did not decode, dropped."""

    def take(self, max_samples: int = _TAKE_LIMIT) -> list[T]:
        """The samples that arrived since the last call, oldest first (non-blocking).

        Args:
            max_samples: at most this many are taken; the rest wait for the next call.

        Raises:
            BridgeError: the participant is closed or Cyclone DDS fails.
        """
        if self._reader is None:
            raise BridgeError(f"subscription on {self.ros_topic} is closed; expected an open one")
        samples: list[T] = []
        # One at a time, so that a sample that does not decode costs only itself: a batch
        # is taken out of the reader before it is decoded.
        for _ in range(max_samples):
            try:
                batch: Sequence[object] = self._reader.take(N=1)
            except DDSException as exc:
                raise BridgeError(f"cannot take from {self.ros_topic} ({_cyclone(exc)})") from exc
            except Exception:  # any decoding failure (e.g. a string that is not UTF-8)
                self.malformed += 1
                continue
            if not batch:
                break
            # a dataless sample (an InvalidSample: a writer left) carries no message
            samples.extend(sample for sample in batch if isinstance(sample, self._idl_type))
        self.received += len(samples)
        return samples

    def _close(self) -> None:
        self._reader = None


class RosParticipant:
    """A Cyclone DDS domain participant for ROS 2 topics; a context manager.

    Participants of one process on one domain share Cyclone's domain, so they must ask
    for the same network configuration; the domain is deleted with the last of them.

    Args:
        domain: the DDS domain id (``ROS_DOMAIN_ID``), 0 to 232.
        interface: None for loopback only, else the name or address of the network
            interface to use, with multicast discovery.

    Raises:
        BridgeError: the domain id is out of range, the interface does not exist, or
            Cyclone DDS cannot create the participant.
    """

    def __init__(self, domain: int = 0, *, interface: str | None = None) -> None:
        if not 0 <= domain <= MAX_DOMAIN:
            raise BridgeError(f"DDS domain {domain} is out of range; expected 0..{MAX_DOMAIN}")
        network = _network(interface)
        self.domain = domain
        self.interface = interface
        with _DOMAINS:
            shared, participant = _join(domain, network)
        self._domain: _ConfiguredDomain | None = shared
        self._participant: DomainParticipant | None = participant
        try:
            self._discovery: _Discovery | None = _Discovery(participant)
        except DDSException as exc:
            raise BridgeError(
                f"cannot read discovery on DDS domain {domain} ({_cyclone(exc)})"
            ) from exc
        self._endpoints: list[Publisher[Any] | Subscription[Any]] = []

    def __enter__(self) -> RosParticipant:
        return self

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        traceback: TracebackType | None,
    ) -> None:
        self.close()

    def _closed(self) -> BridgeError:
        return BridgeError(
            f"participant on DDS domain {self.domain} is closed; expected an open one"
        )

    def _require(self) -> DomainParticipant:
        if self._participant is None:
            raise self._closed()
        return self._participant

    def _topic(self, ros_topic: str, idl_type: type[T]) -> Topic[T]:
        participant = self._require()
        try:
            return Topic(participant, dds_topic(ros_topic), idl_type)
        except DDSException as exc:
            raise BridgeError(f"cannot create a topic {ros_topic} ({_cyclone(exc)})") from exc

    def publisher(self, ros_topic: str, idl_type: type[T], qos_kind: QosKind) -> Publisher[T]:
        """A publisher of ``idl_type`` samples on ``ros_topic`` with a ROS 2 QoS profile.

        Raises:
            ValueError: ``ros_topic`` is not a valid absolute ROS 2 name.
            BridgeError: the participant is closed or Cyclone DDS fails.
        """
        topic = self._topic(ros_topic, idl_type)
        try:
            writer = DataWriter(self._require(), topic, qos=qos_for(qos_kind))
        except DDSException as exc:
            raise BridgeError(f"cannot create a writer on {ros_topic} ({_cyclone(exc)})") from exc
        publisher: Publisher[T] = Publisher(ros_topic, writer)
        self._endpoints.append(publisher)
        return publisher

    def subscription(self, ros_topic: str, idl_type: type[T], qos_kind: QosKind) -> Subscription[T]:
        """A subscription to ``idl_type`` samples on ``ros_topic`` with a ROS 2 QoS profile.

        Raises:
            ValueError: ``ros_topic`` is not a valid absolute ROS 2 name.
            BridgeError: the participant is closed or Cyclone DDS fails.
        """
        topic = self._topic(ros_topic, idl_type)
        try:
            reader = DataReader(self._require(), topic, qos=qos_for(qos_kind))
        except DDSException as exc:
            raise BridgeError(f"cannot create a reader on {ros_topic} ({_cyclone(exc)})") from exc
        subscription: Subscription[T] = Subscription(ros_topic, idl_type, reader)
        self._endpoints.append(subscription)
        return subscription

    def foreign_writers(self, ros_topic: str, expected_ros_type: str) -> int:
        """Discovered writers of other participants on ``ros_topic`` with another type.

        Such writers never match this participant's readers (Cyclone DDS checks that
        types are assignable), so their data is silently lost; this makes it visible.
        Non-blocking: it counts what discovery has found so far.

        Args:
            ros_topic: an absolute ROS 2 topic, e.g. ``/robot_0/pose``.
            expected_ros_type: the ROS 2 type it should carry, e.g.
                ``geometry_msgs/msg/PoseStamped``.

        Raises:
            ValueError: ``ros_topic`` or ``expected_ros_type`` is not a valid ROS 2 name.
            BridgeError: the participant is closed or Cyclone DDS fails.
        """
        topic, type_name = dds_topic(ros_topic), dds_type(expected_ros_type)
        if self._discovery is None:
            raise self._closed()
        try:
            alive = self._discovery.writers()
        except DDSException as exc:
            raise BridgeError(
                f"cannot read the writers discovered on {ros_topic} ({_cyclone(exc)})"
            ) from exc
        return sum(
            1
            for endpoint in alive
            if endpoint.topic_name == topic
            and endpoint.type_name != type_name
            and endpoint.participant_key != self._discovery.own
        )

    def close(self) -> None:
        """Delete the participant, its writers and readers (and the domain if last).

        Cyclone DDS deletes an entity when its Python object goes, so closing drops every
        reference this participant holds; publishers and subscriptions refuse use after.
        """
        for endpoint in self._endpoints:
            endpoint._close()
        self._endpoints.clear()
        self._discovery = None
        with _DOMAINS:  # the domain may go with the last reference, see _join
            self._participant = None
            self._domain = None

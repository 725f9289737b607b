"""The Unity endpoint: a ROS-TCP-Endpoint served by the run itself, for ROS-TCP-Connector scenes.

Unity connects as the TCP client (the Connector's ROS IP and port). Each connection is its
own session (:mod:`adapters.unity.connection`): its handshake first, then the topics it
subscribed to, with the bytes the bag records; what it registered dies with it, as the
Connector re-registers everything when it reconnects. The endpoint is a sink of the run's
recording (its ``open``, ``write`` and ``close`` take the recorded topics and messages).
Goals a scene publishes are queued by the connection's reader thread and published on the
run's bus by the kernel (every :data:`DRAIN_EVERY_NS`): only the kernel's thread touches
the run.
"""

from __future__ import annotations

import contextlib
import itertools
import queue
import socket
import threading
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any, ClassVar, Protocol

from adapters.drivers.topics import teleop_topic
from adapters.navigation.topics import goal_topic
from adapters.unity import framing as frames
from adapters.unity.commands import handle
from adapters.unity.connection import Connection
from adapters.unity.inbound import (
    GOAL_TYPE,
    TWIST_TYPE,
    UnityGoal,
    UnityPose,
    UnityTwist,
    goal_topics,
    pose_topics,
    teleop_topics,
    unity_name,
)
from cosim.core.bus import Bus, TopicQos
from cosim.core.errors import BridgeError
from cosim.core.hosts import HostId
from cosim.core.kernel import Stage
from cosim.core.messages import NavGoal, PoseStamped, Twist
from cosim.core.summary import SummaryKey

DRAIN_EVERY_NS = 50_000_000
"""Goals from Unity enter the run at most 50 ms (simulated) after they arrived."""
GOAL_IDS = 2**31
"""Goal ids from Unity start here, apart from the run's own goal senders' ids."""
COUNTS = ("unity_clients", "unity_frames_received", "unity_frames_rejected", "unity_goals")
"""Summary keys, plus ``unity_frames_dropped`` for frames a slow connection missed and
``unity_twists`` / ``unity_poses`` for velocity commands and tracked poses taken (when the
run takes them)."""
MOCAP_HOST = HostId("mocap")
"""The host tracked poses from Unity are published from (the mocap adapter's)."""


def peer_name(address: Any) -> str:
    """``127.0.0.1:53412`` (``[::1]:53412`` for IPv6) of an accepted connection's address."""
    if isinstance(address, tuple) and len(address) >= 2:
        host = str(address[0])
        return f"[{host}]:{address[1]}" if ":" in host else f"{host}:{address[1]}"
    return str(address)


class Channel(Protocol):
    """A recorded topic as the endpoint serves it (the recording's ``ChannelSpec``)."""

    @property
    def topic(self) -> str:
        """The topic."""
        ...

    @property
    def msgtype(self) -> str:
        """Its ROS 2 type, ``pkg/msg/Type``."""
        ...

    @property
    def qos(self) -> TopicQos:
        """How it is offered (a latched topic's last message goes to late subscribers)."""
        ...


@dataclass(frozen=True, slots=True)
class UnityOptions:
    """Where the run serves Unity.

    Attributes:
        host: address to bind (``127.0.0.1``: this machine only).
        port: TCP port (10000: the ROS-TCP-Endpoint's and the Connector's default; 0: any).
    """

    host: str = "127.0.0.1"
    port: int = 10000


class UnitySink:
    """Serves recorded topics to Unity scenes and takes their goals into the run.

    Args:
        options: host and port.
        bus: the run's bus (goals are published on it; its kernel drains them).
    """

    summary_keys: ClassVar[Mapping[str, SummaryKey]] = {
        "unity_clients": SummaryKey("count", "connections Unity scenes opened"),
        "unity_frames_received": SummaryKey("count", "ROS-TCP frames received from the scenes"),
        "unity_frames_rejected": SummaryKey(
            "count", "frames refused (malformed, or an unknown topic or type)"
        ),
        "unity_goals": SummaryKey("count", "navigation goals taken from the scenes"),
        "unity_frames_dropped": SummaryKey(
            "count",
            "frames a connection too slow to take them missed",
            when="a frame was dropped",
        ),
        "unity_twists": SummaryKey(
            "count",
            "velocity commands taken from the scenes",
            when="robots.driver = 'teleop'",
        ),
        "unity_poses": SummaryKey(
            "count",
            "tracked poses taken from the scenes",
            when="mocap.source = 'unity'",
        ),
    }

    def __init__(self, options: UnityOptions, bus: Bus) -> None:
        self.options = options
        self.bus = bus
        self.channels: list[Channel] = []
        self.by_topic: dict[str, int] = {}
        self.goal_topics: dict[str, str] = {}
        self.goals: queue.SimpleQueue[UnityGoal] = queue.SimpleQueue()
        self.teleop_topics: dict[str, str] = {}
        self.twists: queue.SimpleQueue[UnityTwist] = queue.SimpleQueue()
        self.pose_topics: dict[str, str] = {}
        self._poses: dict[str, UnityPose] = {}
        """The newest pose of each bus topic since the last drain (older ones are stale)."""
        self.counts = dict.fromkeys(
            (*COUNTS, "unity_frames_dropped", "unity_twists", "unity_poses"), 0
        )
        self.connected = threading.Event()
        self._latched: dict[int, dict[str, bytes]] = {}
        self._clients: list[Connection] = []
        self._lock = threading.Lock()
        self._server: socket.socket | None = None
        self._accepting: threading.Thread | None = None
        self._stopping = threading.Event()
        self._goal_ids = itertools.count(GOAL_IDS)

    @property
    def port(self) -> int:
        """The port the server listens on."""
        if self._server is None:
            raise BridgeError("unity: the server is not started")
        return int(self._server.getsockname()[1])

    def open(self, channels: Sequence[Channel]) -> None:
        """Listen, and have the kernel take Unity's goals into the run.

        Raises:
            BridgeError: naming ``--unity-port`` or ``--unity-host`` when it cannot listen.
        """
        host, port = self.options.host, self.options.port
        try:
            family = socket.getaddrinfo(host, port, type=socket.SOCK_STREAM)[0][0]
            self._server = socket.create_server((host, port), family=family)
        except OSError as error:
            reason = error.strerror or str(error)
            if error.errno == 98 or "in use" in reason.lower():
                raise BridgeError(
                    f"--unity-port {port}: cannot serve Unity on {host}:{port} ({reason}); "
                    "expected a free port (a ROS-TCP-Endpoint or another `cosim run --unity` "
                    "may hold it: try another --unity-port)"
                ) from None
            raise BridgeError(
                f"--unity-host {host} --unity-port {port}: cannot serve Unity there ({reason}); "
                "expected an address of this machine (127.0.0.1, 0.0.0.0) and a free port"
            ) from None
        self._server.settimeout(0.2)
        self.channels = list(channels)
        self.by_topic = {spec.topic: i for i, spec in enumerate(self.channels)}
        self._latched = {
            i: {} for i, spec in enumerate(self.channels) if spec.qos is TopicQos.LATCHED
        }
        self.goal_topics = goal_topics(self.bus.advertised())
        self.teleop_topics = teleop_topics(self.bus.advertised())
        self.pose_topics = pose_topics(self.bus.advertised())
        self.bus.kernel.every(DRAIN_EVERY_NS, self._drain, stage=Stage.CONTROL)
        self._accepting = threading.Thread(target=self._accept, name="unity-accept", daemon=True)
        self._accepting.start()

    def _accept(self) -> None:
        server = self._server
        assert server is not None
        while not self._stopping.is_set():
            try:
                conn, address = server.accept()
            except TimeoutError:
                continue
            except OSError:
                return
            conn.settimeout(None)
            client = Connection(self, conn, handle, peer=peer_name(address))
            with self._lock:
                self._clients.append(client)
                self.counts["unity_clients"] += 1
            client.start()
            self.connected.set()

    def write(self, channel: int, t_ns: int, data: bytes, src: str = "") -> None:
        """Send one message to the connections subscribed to its topic (kernel thread)."""
        topic = self.channels[channel].topic
        message = frames.frame(topic, data)
        latched = self._latched.get(channel)
        if latched is not None:
            with self._lock:
                latched[src] = message
        for client in self._clients:
            if topic in client.subscriptions:
                client.send(message)

    def latched(self, topic: str) -> list[bytes]:
        """The last frame of each publisher of a latched topic (for a late subscriber)."""
        with self._lock:
            return list(self._latched.get(self.by_topic.get(topic, -1), {}).values())

    def topic_list(self) -> dict[str, list[str]]:
        """``__topic_list``'s answer: served topics, goal and teleop topics, Unity's types."""
        listed = {spec.topic: spec.msgtype for spec in self.channels}
        listed.update(dict.fromkeys(self.goal_topics, GOAL_TYPE))
        listed.update(dict.fromkeys(self.teleop_topics, TWIST_TYPE))
        listed.update(dict.fromkeys(self.pose_topics, GOAL_TYPE))
        return {"topics": list(listed), "types": [unity_name(t) for t in listed.values()]}

    def count(self, key: str) -> None:
        """One more of ``key`` (from any thread)."""
        with self._lock:
            self.counts[key] += 1

    def take_pose(self, pose: UnityPose) -> None:
        """Keep ``pose`` as its topic's newest (a reader thread)."""
        with self._lock:
            self._poses[pose.bus_topic] = pose

    def _drain(self, now_ns: int) -> None:
        """Publish the goals and commands Unity sent since the last call (kernel thread)."""
        while True:
            try:
                twist = self.twists.get_nowait()
            except queue.Empty:
                break
            command = Twist(twist.linear_x_mps, twist.angular_z_radps)
            self.bus.publish(teleop_topic(twist.robot), command, HostId(twist.robot))
            self.count("unity_twists")
        with self._lock:
            poses, self._poses = list(self._poses.values()), {}
        for pose in poses:  # stamped on arrival here: Unity's clock is not the run's
            seen = PoseStamped(now_ns, "map", pose.x_m, pose.y_m, pose.yaw_rad)
            self.bus.publish(pose.bus_topic, seen, MOCAP_HOST)
            self.count("unity_poses")
        while True:
            try:
                goal = self.goals.get_nowait()
            except queue.Empty:
                return
            message = NavGoal(now_ns, next(self._goal_ids), goal.x_m, goal.y_m, goal.yaw_rad)
            self.bus.publish(goal_topic(goal.robot), message, HostId(goal.robot))
            self.count("unity_goals")

    def summary(self) -> dict[str, int]:
        """Connections, frames received and refused, goals taken (the run's summary)."""
        with self._lock:
            counts = dict(self.counts)
        if not counts["unity_frames_dropped"]:
            del counts["unity_frames_dropped"]
        if not self.teleop_topics:
            del counts["unity_twists"]
        if not self.pose_topics:
            del counts["unity_poses"]
        return counts

    def close(self) -> None:
        """Stop listening and end every connection."""
        self._stopping.set()
        if self._server is not None:
            with contextlib.suppress(OSError):  # wakes accept() at once
                self._server.shutdown(socket.SHUT_RDWR)
        if self._accepting is not None:
            self._accepting.join(timeout=2.0)
        if self._server is not None:
            self._server.close()
        with self._lock:
            clients = list(self._clients)
        for client in clients:
            client.stop()
        for client in clients:
            client.join()

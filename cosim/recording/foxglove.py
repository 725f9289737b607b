"""The live view: a run served over the Foxglove WebSocket protocol while it goes.

The official ``foxglove-sdk`` server advertises one channel per recorded topic with the
same schema (``ros2msg``) and the same CDR bytes as the bag, so Foxglove decodes them as it
decodes a ROS 2 bridge; the run is paced by the real-time kernel. The server also
broadcasts the simulation time (Foxglove's ``time`` capability), and a viewer that
subscribes to a latched topic (``/map``, ``/tf_static``, ``/world/markers``) after it was
published gets each publisher's last message again, as ROS 2's transient-local
durability gives a late subscriber.
"""

from __future__ import annotations

import threading
from collections.abc import Sequence
from dataclasses import dataclass

import foxglove
from foxglove.websocket import Capability, ChannelView, Client, ServerListener, WebSocketServer

from cosim.core.bus import TopicQos
from cosim.core.errors import BridgeError
from cosim.recording.schemas import ChannelSpec

TIME_EVERY_NS = 50_000_000
"""Simulation time is broadcast to viewers at most every 50 ms of it."""


@dataclass(frozen=True, slots=True)
class LiveOptions:
    """Where and how fast the live view serves a run.

    Attributes:
        host: address to bind (``127.0.0.1``: this machine only).
        port: TCP port (0: any free port).
        rate: simulated seconds per wall-clock second (1.0: real time).
        wait: hold the run until a viewer subscribes to a topic.
    """

    host: str = "127.0.0.1"
    port: int = 8765
    rate: float = 1.0
    wait: bool = False


class _Listener(ServerListener):
    """Forwards the server's subscription events (called on the server's thread)."""

    def __init__(self, sink: LiveSink) -> None:
        self.sink = sink

    def on_subscribe(self, client: Client, channel: ChannelView) -> None:
        """A viewer subscribed to a channel."""
        self.sink.subscribed_to(channel.id)


class LiveSink:
    """Serves recorded topics to Foxglove viewers over WebSocket.

    Args:
        options: host, port, pace.
    """

    def __init__(self, options: LiveOptions) -> None:
        self.options = options
        self._context = foxglove.Context()
        self._server: WebSocketServer | None = None
        self._channels: list[foxglove.Channel] = []
        self._latched: dict[int, dict[str, bytes]] = {}
        self._by_id: dict[int, int] = {}
        self._last_time_ns = -TIME_EVERY_NS
        self._lock = threading.Lock()
        self.subscribed = threading.Event()

    @property
    def port(self) -> int:
        """The port the server listens on."""
        if self._server is None:
            raise BridgeError("live view: the server is not started")
        return int(self._server.port)

    @property
    def url(self) -> str:
        """The address to open in Foxglove."""
        return f"ws://{self.options.host}:{self.port}"

    def open(self, channels: Sequence[ChannelSpec]) -> None:
        """Start the server and advertise every channel.

        Raises:
            BridgeError: naming host and port when the server cannot listen there.
        """
        host, port = self.options.host, self.options.port
        try:
            self._server = foxglove.start_server(
                name="cosim",
                host=host,
                port=port,
                capabilities=[Capability.Time],
                server_listener=_Listener(self),
                supported_encodings=["cdr"],
                context=self._context,
            )
        except RuntimeError as error:
            reason = str(error).removeprefix("FoxgloveError: ")
            if "in use" not in reason.lower():  # not the port: the address (or the system)
                raise BridgeError(
                    f"--live-host {host} --live-port {port}: cannot serve the live view there "
                    f"({reason}); expected an address of this machine (127.0.0.1, 0.0.0.0) "
                    "and a free port"
                ) from None
            raise BridgeError(
                f"--live-port {port}: cannot serve the live view on {host}:{port} ({reason}); "
                "expected a free port (another `cosim run --live` or a Foxglove bridge may "
                "hold it: try another --live-port)"
            ) from None
        for index, spec in enumerate(channels):
            schema = foxglove.Schema(
                name=spec.msgtype, encoding="ros2msg", data=spec.msgdef.encode("utf-8")
            )
            channel = foxglove.Channel(
                spec.topic, schema=schema, message_encoding="cdr", context=self._context
            )
            self._channels.append(channel)
            self._by_id[channel.id()] = index
            if spec.qos is TopicQos.LATCHED:
                self._latched[index] = {}

    def write(self, channel: int, t_ns: int, data: bytes, src: str = "") -> None:
        """Send one message to the viewers subscribed to its channel."""
        self._channels[channel].log(data, log_time=t_ns)
        latched = self._latched.get(channel)
        if latched is not None:
            with self._lock:
                latched[src] = data
        if t_ns - self._last_time_ns >= TIME_EVERY_NS and self._server is not None:
            self._server.broadcast_time(t_ns)
            self._last_time_ns = t_ns

    def subscribed_to(self, channel_id: int) -> None:
        """A viewer subscribed: give it the last message of a latched topic (server thread)."""
        index = self._by_id.get(channel_id)
        if index is not None and index in self._latched:
            with self._lock:
                last = list(self._latched[index].values())
            for data in last:
                self._channels[index].log(data, log_time=max(self._last_time_ns, 0))
        self.subscribed.set()

    def close(self) -> None:
        """Stop the server."""
        server, self._server = self._server, None
        for channel in self._channels:
            channel.close()
        if server is not None:
            server.stop()

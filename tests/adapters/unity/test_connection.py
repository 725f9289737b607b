"""One scene's connection over a socket pair: handshake, frames handled, refusals, its end."""

from __future__ import annotations

import json
import socket
import struct
import threading
from collections import Counter
from collections.abc import Iterator

import pytest

import adapters.unity.connection as connection
from adapters.unity import framing
from adapters.unity.connection import Connection


class Sink:
    """Counts what a connection counts (from its threads)."""

    def __init__(self) -> None:
        self.counts: Counter[str] = Counter()
        self.lock = threading.Lock()

    def count(self, key: str) -> None:
        with self.lock:
            self.counts[key] += 1


class Scene:
    """The scene's end of a connection, and what the connection handed its handler."""

    def __init__(self, handler=None) -> None:
        self.sink = Sink()
        self.unity, served = socket.socketpair()
        self.unity.settimeout(5.0)
        self.handled: list[tuple[str, bytes]] = []
        self.done = threading.Event()
        self.connection = Connection(self.sink, served, handler or self.keep)

    def keep(self, client: Connection, destination: str, payload: bytes) -> None:
        assert client is self.connection
        self.handled.append((destination, payload))
        if destination == "/done":
            self.done.set()

    def read(self) -> tuple[str, bytes]:
        got = framing.read_frame(self.unity)
        assert got is not None
        return got

    def until(self, destination: str) -> bytes:
        while True:
            got, payload = self.read()
            if got == destination:
                return payload


@pytest.fixture
def scene() -> Iterator[Scene]:
    scene = Scene()
    scene.connection.start()
    yield scene
    scene.connection.stop()
    scene.connection.join()
    scene.unity.close()


def test_the_first_frame_sent_is_the_handshake(scene: Scene):
    destination, payload = scene.read()
    assert framing.frame(destination, payload) == framing.handshake()
    assert destination == "__handshake" and json.loads(payload)["version"] == framing.VERSION


def test_every_frame_from_the_scene_is_handed_to_the_handler_in_order_and_counted(scene: Scene):
    scene.unity.sendall(
        framing.KEEPALIVE
        + framing.frame("/robot_1/goal_pose", b"cdr")
        + framing.frame("/done", b"")
    )
    assert scene.done.wait(5.0)
    assert scene.handled == [("", b""), ("/robot_1/goal_pose", b"cdr"), ("/done", b"")]
    assert scene.sink.counts["unity_frames_received"] == 3


def test_frames_queued_for_the_scene_are_sent_in_order(scene: Scene):
    scene.connection.send(framing.frame("/a", b"1"))
    scene.connection.send(framing.frame("/b", b"2"))
    assert [scene.read() for _ in range(3)][1:] == [("/a", b"1"), ("/b", b"2")]


def test_a_refused_frame_is_answered_with_an_error_counted_and_the_connection_goes_on():
    def refuse_odd(client: Connection, destination: str, payload: bytes) -> None:
        if destination == "/odd":
            raise ValueError("'/odd' is not a topic of this run")
        client.send(framing.frame("/echo", payload))

    scene = Scene(refuse_odd)
    scene.connection.start()
    try:
        scene.unity.sendall(framing.frame("/odd", b"") + framing.frame("/even", b"x"))
        text = json.loads(scene.until("__error"))["text"]
        assert text == "cosim: '/odd' is not a topic of this run"
        assert scene.until("/echo") == b"x"  # still served
        assert scene.sink.counts["unity_frames_rejected"] == 1
    finally:
        scene.connection.stop()
        scene.connection.join()
        scene.unity.close()


def test_a_frame_breaking_the_protocol_is_answered_and_ends_the_connection(scene: Scene):
    scene.unity.sendall(struct.pack("<I", framing.MAX_DESTINATION_BYTES + 1))
    text = json.loads(scene.until("__error"))["text"]
    assert text == "cosim: destination of 1025 bytes; expected at most 1024; closing the connection"
    assert framing.read_frame(scene.unity) is None  # closed after the error went out
    assert scene.sink.counts["unity_frames_rejected"] == 1
    assert scene.connection.closed.wait(5.0)


def test_the_scene_closing_ends_the_connection(scene: Scene):
    scene.read()
    scene.unity.shutdown(socket.SHUT_WR)
    assert scene.connection.closed.wait(5.0)
    assert framing.read_frame(scene.unity) is None


def test_an_idle_connection_gets_a_keepalive(monkeypatch):
    monkeypatch.setattr(connection, "KEEPALIVE_S", 0.05)
    scene = Scene()
    scene.connection.start()
    try:
        assert scene.read()[0] == "__handshake"
        assert scene.read() == ("", b"")
    finally:
        scene.connection.stop()
        scene.connection.join()
        scene.unity.close()


def test_frames_for_a_connection_too_slow_to_take_them_are_dropped_and_counted(monkeypatch):
    monkeypatch.setattr(connection, "QUEUE_FRAMES", 3)
    scene = Scene()  # not started: nothing leaves the queue, which holds the handshake
    for k in range(5):
        scene.connection.send(framing.frame("/scan", bytes([k])))
    assert scene.sink.counts["unity_frames_dropped"] == 3
    assert scene.connection.outbox.qsize() == 3
    scene.unity.close()
    scene.connection.conn.close()


def test_nothing_is_queued_once_the_connection_is_stopped():
    scene = Scene()
    scene.connection.stop()
    scene.connection.send(framing.frame("/scan", b"late"))
    queued = []
    while not scene.connection.outbox.empty():
        queued.append(scene.connection.outbox.get_nowait())
    assert queued == [framing.handshake(), None]  # the end, and nothing after it
    assert scene.sink.counts["unity_frames_dropped"] == 0
    scene.connection.stop()  # once only
    scene.unity.close()
    scene.connection.conn.close()


def test_read_next_takes_the_following_frames_payload_and_counts_it():
    scene = Scene()
    scene.unity.sendall(framing.frame("", b"the payload"))
    assert scene.connection.read_next() == b"the payload"
    assert scene.sink.counts["unity_frames_received"] == 1
    scene.unity.close()
    with pytest.raises(framing.FrameError, match="connection closed before a service payload"):
        scene.connection.read_next()
    scene.connection.conn.close()


def test_a_frame_the_handler_fails_on_otherwise_ends_that_connection_in_one_line(
    monkeypatch, caplog
):
    died: list[threading.ExceptHookArgs] = []
    monkeypatch.setattr(threading, "excepthook", died.append)

    def overflow(client: Connection, destination: str, payload: bytes) -> None:
        raise RecursionError("maximum recursion depth exceeded\nwhile decoding")

    scene = Scene(overflow)
    scene.connection.peer = "127.0.0.1:5000"
    scene.connection.start()
    try:
        scene.unity.sendall(framing.frame("__subscribe", b"[[[["))
        text = json.loads(scene.until("__error"))["text"]
        assert text == (
            "cosim: cannot handle a frame (RecursionError: maximum recursion depth exceeded "
            "while decoding); closing the connection"
        )
        assert framing.read_frame(scene.unity) is None  # closed after the error went out
        assert scene.connection.closed.wait(5.0)
        scene.connection.join()
    finally:
        scene.connection.stop()
        scene.unity.close()
    assert died == []  # the reader thread ended as it does on a clean close
    assert scene.sink.counts["unity_frames_rejected"] == 1
    assert caplog.messages == [
        "unity: refused a frame from 127.0.0.1:5000: cannot handle a frame (RecursionError: "
        "maximum recursion depth exceeded while decoding); closing the connection"
    ]


def test_the_first_refusals_of_a_connection_are_logged_naming_the_peer_the_rest_counted(caplog):
    def refuse(client: Connection, destination: str, payload: bytes) -> None:
        raise ValueError(f"{destination!r} is not a topic of this run")

    scene = Scene(refuse)
    scene.connection.peer = "[::1]:6000"
    scene.connection.start()
    try:
        count = connection.LOGGED_REFUSALS + 3
        scene.unity.sendall(b"".join(framing.frame(f"/t{k}", b"") for k in range(count)))
        for _ in range(count):
            scene.until("__error")
    finally:
        scene.connection.stop()
        scene.connection.join()
        scene.unity.close()
    assert scene.sink.counts["unity_frames_rejected"] == count
    assert len(caplog.records) == connection.LOGGED_REFUSALS
    assert {r.levelname for r in caplog.records} == {"WARNING"}
    assert (
        caplog.messages[0]
        == "unity: refused a frame from [::1]:6000: '/t0' is not a topic of this run"
    )
    assert caplog.messages[-1].endswith(
        f"'/t{connection.LOGGED_REFUSALS - 1}' is not a topic of this run; its further refusals "
        "are only counted"
    )

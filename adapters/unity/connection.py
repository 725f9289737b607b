"""One Unity scene's connection: its subscriptions and registrations, its two threads.

A reader thread takes the scene's frames and acts on each (:func:`adapters.unity.commands.handle`,
given by the endpoint); a writer thread sends the frames queued for the scene, and a
keepalive after :data:`KEEPALIVE_S` without anything, so the Connector never takes an idle
run for a lost one. A frame that breaks the protocol ends the connection (the Connector
reconnects); a refused one is answered with ``__error`` and counted. Whatever the bytes,
the reader thread never dies of them: anything else that goes wrong handling a frame ends
that connection the same way, in one line. Each refusal is logged in one line naming the
peer (logger ``adapters.unity``, a warning: on stderr unless the application configures
logging), the first :data:`LOGGED_REFUSALS` of a connection; the rest are counted only.
"""

from __future__ import annotations

import contextlib
import logging
import queue
import socket
import threading
from collections.abc import Callable
from typing import Any

from adapters.unity import framing as frames

KEEPALIVE_S = 1.0
"""A connection idle this long (wall-clock s) gets a keepalive."""
QUEUE_FRAMES = 10_000
"""Frames waiting for a slow connection; more are dropped (and counted)."""
LOGGED_REFUSALS = 5
"""Refusals of one connection logged; the later ones are counted (``unity_frames_rejected``)."""
LINE_CHARS = 300
"""A logged line is cut to this many characters (a refusal may quote what the scene sent)."""
LOG = logging.getLogger("adapters.unity")

Handler = Callable[["Connection", str, bytes], None]
"""What acts on one frame (destination, payload); raises ValueError to refuse it."""


class Connection:
    """One connection: its subscriptions, its registered goal topics, its two threads.

    Args:
        sink: the endpoint (its counts, and what ``handle`` acts on).
        conn: the connected socket.
        handle: what acts on each frame.
        peer: who is connected, for the log (``127.0.0.1:53412``).
    """

    def __init__(self, sink: Any, conn: socket.socket, handle: Handler, peer: str = "") -> None:
        self.sink = sink
        self.conn = conn
        self.handle = handle
        self.peer = peer or "a scene"
        self.refusals = 0
        self.subscriptions: frozenset[str] = frozenset()
        self.publishes: dict[str, str] = {}
        self.outbox: queue.Queue[bytes | None] = queue.Queue(QUEUE_FRAMES)
        self.outbox.put(frames.handshake())  # before anything else can be queued
        self.closed = threading.Event()
        self.threads = [
            threading.Thread(target=self._send_loop, name="unity-send", daemon=True),
            threading.Thread(target=self._read_loop, name="unity-read", daemon=True),
        ]

    def start(self) -> None:
        """Start reading and writing."""
        for thread in self.threads:
            thread.start()

    def send(self, data: bytes) -> None:
        """Queue a frame; a connection too slow to take it loses it (counted)."""
        if self.closed.is_set():
            return
        try:
            self.outbox.put_nowait(data)
        except queue.Full:
            self.sink.count("unity_frames_dropped")

    def _send_loop(self) -> None:
        try:
            while not self.closed.is_set():
                try:
                    item = self.outbox.get(timeout=KEEPALIVE_S)
                except queue.Empty:
                    item = frames.KEEPALIVE
                if item is None:
                    return
                self.conn.sendall(item)
        except OSError:
            pass
        finally:
            self.stop()

    def _read_loop(self) -> None:
        try:
            while not self.closed.is_set():
                got = frames.read_frame(self.conn)
                if got is None:
                    return
                self.sink.count("unity_frames_received")
                self._handle(*got)
        except frames.FrameError as problem:  # the stream is lost: the Connector reconnects
            self._refuse(f"{problem}; closing the connection")
        except OSError:
            pass
        except Exception as problem:  # whatever a scene sent, the thread ends cleanly
            what = f"{type(problem).__name__}: {problem}"
            self._refuse(f"cannot handle a frame ({what}); closing the connection")
        finally:
            self._end_after_sending()

    def _refuse(self, line: str) -> None:
        """Count a refused frame, answer it with ``__error`` and log it (one line each)."""
        line = " ".join(line.splitlines())  # one line, whatever an exception said
        self.sink.count("unity_frames_rejected")
        self.send(frames.error(f"cosim: {line}"))
        self.refusals += 1
        if self.refusals > LOGGED_REFUSALS:
            return
        last = "; its further refusals are only counted" if self.refusals == LOGGED_REFUSALS else ""
        LOG.warning("unity: refused a frame from %s: %s%s", self.peer, line[:LINE_CHARS], last)

    def _end_after_sending(self) -> None:
        """Unity is gone or lost: send what is queued (an ``__error``), then end."""
        try:
            self.outbox.put(None, timeout=KEEPALIVE_S)
        except queue.Full:
            self.stop()

    def _handle(self, destination: str, payload: bytes) -> None:
        try:
            self.handle(self, destination, payload)
        except ValueError as problem:
            self._refuse(str(problem))

    def read_next(self) -> bytes:
        """The payload of the frame after ``__request``/``__response``."""
        got = frames.read_frame(self.conn)
        if got is None:
            raise frames.FrameError("connection closed before a service payload")
        self.sink.count("unity_frames_received")
        return got[1]

    def stop(self) -> None:
        """End the connection (from any thread; once)."""
        if self.closed.is_set():
            return
        self.closed.set()
        with contextlib.suppress(queue.Full):
            self.outbox.put_nowait(None)
        with contextlib.suppress(OSError):
            self.conn.shutdown(socket.SHUT_RDWR)

    def join(self) -> None:
        """Wait for both threads (not the calling one), then close the socket."""
        for thread in self.threads:
            if thread is not threading.current_thread():
                thread.join(timeout=2.0)
        self.conn.close()

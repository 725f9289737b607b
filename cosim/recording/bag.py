"""The bag of a run: a rosbag2 directory written while the run goes, with rosbags' Writer.

MCAP by default (what ``ros2 bag`` records since Iron, and what Foxglove opens), sqlite3
(``.db3``) on request; metadata version 8, which Humble's rosbag2 and every later one
read. Messages are written as they are published: MCAP closes a chunk every MiB (zstd
compressed, as rosbag2's default MCAP profile does), so memory stays flat however long
the run, and a run killed mid-way leaves a file whose complete chunks still read with a
streaming MCAP reader (the index and ``metadata.yaml`` come at the end). A sqlite3 bag
commits every :data:`COMMIT_EVERY` messages for the same reason.
"""

from __future__ import annotations

import contextlib
import sqlite3
import struct
import sys
from collections.abc import Mapping, Sequence
from pathlib import Path
from types import MappingProxyType
from typing import Any, Final, Literal

from rosbags.interfaces import Connection
from rosbags.rosbag2 import StoragePlugin, Writer, WriterError
from rosbags.rosbag2.enums import CompressionFormat, CompressionMode
from rosbags.rosbag2.storage_mcap import McapWriter

from cosim.core.errors import ExportError
from cosim.recording.schemas import ChannelSpec, recorded_qos

if sys.version_info >= (3, 14):  # pragma: no cover
    from compression import zstd
else:
    from backports import zstd

BAG_DIR = "bag"
"""The bag's folder inside a run folder."""
METADATA_VERSION: Final[Literal[8]] = 8
"""rosbag2 metadata version: 8 is read by Humble and every later distribution."""
COMMIT_EVERY = 10_000
"""A sqlite3 bag commits after this many messages (what a killed run leaves)."""
STORAGE = {"mcap": StoragePlugin.MCAP, "sqlite3": StoragePlugin.SQLITE3}
CHUNK_BYTES = 2**20
"""An MCAP chunk is closed (compressed and written) past this size, as rosbags does."""


ZSTD_LEVEL = 1
"""zstd level of MCAP chunks and sqlite3 messages: faster than rosbags' default (3) for about
the same ratio on our chunks, as rosbag2's ``zstd_fast`` preset chooses speed
(``bench/recording_bench.py``)."""


def _fast_zstd(data: bytes) -> bytes:
    return zstd.compress(data, level=ZSTD_LEVEL)


_MESSAGE_RECORD = struct.Struct("<BQHIQQ")
"""An MCAP Message record's opcode, length, channel id, sequence, log and publish times."""


class _StreamingMcapWriter(McapWriter):
    """rosbags' MCAP storage, its per-message record packed in one call.

    rosbags builds each Message record field by field in a fresh buffer; at a few
    thousand messages per simulated second that was most of a recorded run's extra cost
    (``make bench``). The bytes are the same (a test compares the files); chunks, indexes
    and the summary are rosbags' own.
    """

    def __init__(self, path: Path, compression: CompressionMode) -> None:
        super().__init__(path, compression)
        if compression == CompressionMode.STORAGE:
            self.compressor = _fast_zstd

    def write(self, connection: Connection, timestamp: int, data: bytes | memoryview) -> None:
        """Append one Message record to the open chunk (see ``McapWriter.write``)."""
        if timestamp < self.message_start_time:
            self.message_start_time = timestamp
        if timestamp > self.message_end_time:
            self.message_end_time = timestamp
        cid = connection.id
        self.channel_stats[cid] += 1
        chunk = self.chunk
        if timestamp < chunk.message_start_time:
            chunk.message_start_time = timestamp
        if timestamp > chunk.message_end_time:
            chunk.message_end_time = timestamp
        bio = chunk.bio
        chunk.msgs[cid].append((timestamp, bio.tell()))
        bio.write(_MESSAGE_RECORD.pack(0x05, 22 + len(data), cid, 0, timestamp, timestamp))
        bio.write(data)
        if bio.tell() > CHUNK_BYTES:
            self.close_chunk()


class _StreamingWriter(Writer):
    """rosbags' Writer storing MCAP through :class:`_StreamingMcapWriter`."""

    STORAGE_PLUGINS: Mapping[StoragePlugin, type[Any]] = MappingProxyType(
        {**Writer.STORAGE_PLUGINS, StoragePlugin.MCAP: _StreamingMcapWriter}
    )


class BagSink:
    """Writes a run's recorded topics into a rosbag2 directory.

    Args:
        path: the bag directory to create (must not exist).
        storage: ``"mcap"`` or ``"sqlite3"``.
        compression: ``"zstd"`` (MCAP chunks; sqlite3 messages) or ``"none"``.
    """

    def __init__(self, path: Path, *, storage: str, compression: str) -> None:
        if storage not in STORAGE:
            raise ExportError(f"bag storage {storage!r}: expected one of {', '.join(STORAGE)}")
        self.path = Path(path)
        self.storage = storage
        self.compression = compression
        self._writer: _StreamingWriter | None = None
        self._connections: list[Connection] = []
        self._since_commit = 0
        self._counts: list[int] = []
        self._first_ns: int | None = None
        self._last_ns = 0
        self._compress = False
        self.messages = 0

    def open(self, channels: Sequence[ChannelSpec]) -> None:
        """Create the bag and a connection per channel.

        Raises:
            ExportError: naming the path if it exists or cannot be created.
        """
        try:
            writer = _StreamingWriter(
                self.path, version=METADATA_VERSION, storage_plugin=STORAGE[self.storage]
            )
            if self.compression == "zstd":
                mode = (
                    CompressionMode.STORAGE if self.storage == "mcap" else CompressionMode.MESSAGE
                )
                # sqlite3: metadata.yaml says "message"; the messages are compressed in write()
                writer.set_compression(mode, CompressionFormat.ZSTD)
            writer.open()
        except (WriterError, OSError) as error:
            raise ExportError(f"{self.path}: cannot create the bag ({error})") from None
        writer.set_custom_data("writer", "cosim")
        self._connections = [
            writer.add_connection(
                spec.topic,
                spec.msgtype,
                msgdef=spec.msgdef,
                rihs01=spec.rihs01,
                offered_qos_profiles=recorded_qos(spec.qos),
            )
            for spec in channels
        ]
        self._writer = writer
        self._counts = [0] * len(self._connections)
        storage = writer.storage
        assert storage is not None
        self._store = storage.write
        # sqlite3 has no chunks: its "zstd" is rosbag2's per-message compression mode
        self._compress = self.compression == "zstd" and self.storage == "sqlite3"

    def write(self, channel: int, t_ns: int, data: bytes, src: str = "") -> None:
        """Store one message of channel ``channel`` (its index in :meth:`open`) at ``t_ns``.

        Straight to rosbags' storage: its ``Writer.write`` finds the connection by a linear
        search of all of them, which costs more than storing the message with a few hundred
        topics (50 robots); the counts and time bounds it keeps are handed to it at
        :meth:`close`. Publication times never decrease, so the first and last message
        bound the bag.
        """
        if self._compress:
            data = zstd.compress(data, level=ZSTD_LEVEL)
        try:
            self._store(self._connections[channel], t_ns, data)
        except (OSError, sqlite3.Error) as error:  # a full disk: the run ends, keeping what ran
            raise ExportError(f"{self.path}: cannot write the bag ({error})") from error
        self._counts[channel] += 1
        if self._first_ns is None:
            self._first_ns = t_ns
        self._last_ns = t_ns
        self.messages += 1
        if self.storage == "sqlite3":
            self._since_commit += 1
            if self._since_commit >= COMMIT_EVERY:
                self._commit()

    def _commit(self) -> None:
        storage = self._writer.storage if self._writer is not None else None
        conn = getattr(storage, "conn", None)
        if conn is not None:
            try:
                conn.commit()
            except sqlite3.Error as error:
                raise ExportError(f"{self.path}: cannot write the bag ({error})") from error
        self._since_commit = 0

    def close(self) -> None:
        """Write the index, the summary and ``metadata.yaml``; the bag is complete."""
        writer, self._writer = self._writer, None
        if writer is not None:
            for connection, count in zip(self._connections, self._counts, strict=True):
                writer.counts[connection.id] = count
            if self._first_ns is not None:
                writer.min_timestamp, writer.max_timestamp = self._first_ns, self._last_ns
            try:
                writer.close()
            except (WriterError, OSError, sqlite3.Error) as error:
                _release(writer.storage)  # a full disk: do not hold its file open too
                raise ExportError(f"{self.path}: cannot finish the bag ({error})") from None

    def files(self) -> list[Path]:
        """The bag's files (storage and ``metadata.yaml``)."""
        return sorted(p for p in self.path.iterdir() if p.is_file())


def _release(storage: Any) -> None:
    """Close the file (MCAP) or database (sqlite3) of a storage that failed to finish."""
    for name in ("bio", "conn"):
        handle = getattr(storage, name, None)
        if handle is not None:
            with contextlib.suppress(Exception):
                handle.close()

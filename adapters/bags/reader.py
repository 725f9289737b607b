"""Reading ROS 2 bags: ours, rosbag2's own, a rosbag2 folder or a bare ``.mcap``/``.db3``.

One code path for every bag a user hands to cosim (``cosim bag info``; later a recording
to map or a mocap log to replay): rosbags' readers, messages decoded with the definitions
the bag itself embeds (so custom types decode without cosim's own). Anything that is
not a readable bag is one :class:`~cosim.core.errors.BagError` line naming the path.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from rosbags.highlevel import AnyReader

from cosim.core.errors import BagError

STORAGE_SUFFIXES = (".mcap", ".db3")


@dataclass(frozen=True, slots=True)
class TopicInfo:
    """One topic of a bag: name, ROS 2 type, message count."""

    name: str
    msgtype: str
    count: int


@dataclass(frozen=True, slots=True)
class BagInfo:
    """What ``cosim bag info`` prints.

    Attributes:
        path: the bag (folder or file).
        storage: ``mcap`` or ``sqlite3``.
        messages: messages in the bag.
        start_ns, end_ns: stamps of the first and last message (ns; 0, 0 when empty).
        topics: per topic, sorted by name.
        files: the bag's storage files and their total size (bytes).
        size_bytes: total size of those files.
    """

    path: Path
    storage: str
    messages: int
    start_ns: int
    end_ns: int
    topics: tuple[TopicInfo, ...]
    files: tuple[Path, ...]
    size_bytes: int

    @property
    def duration_s(self) -> float:
        """Time from the first to the last message (s)."""
        return (self.end_ns - self.start_ns) / 1e9


@dataclass(frozen=True, slots=True)
class BagMessage:
    """A decoded message: topic, ROS 2 type, log time (ns) and the message object."""

    topic: str
    msgtype: str
    t_ns: int
    message: Any


def _check_path(path: Path) -> None:
    """Refuse what cannot be a bag before a reader tries it, with the reason."""
    if not path.exists():
        raise BagError(f"{path}: no such file or folder")
    if path.is_dir():
        if (path / "metadata.yaml").is_file():
            return
        stored = sorted(p.name for p in path.iterdir() if p.suffix in STORAGE_SUFFIXES)
        if stored:
            raise BagError(
                f"{path}: no metadata.yaml next to {', '.join(stored)}: an unfinished bag (was "
                "the run writing it interrupted?); its complete MCAP chunks still read with a "
                "streaming reader, or open the file itself once `ros2 bag reindex` rebuilt it"
            )
        raise BagError(
            f"{path}: not a ROS 2 bag: expected a folder with metadata.yaml, or a .mcap or "
            ".db3 file"
        )
    if path.suffix not in STORAGE_SUFFIXES:
        raise BagError(
            f"{path}: not a ROS 2 bag: expected a .mcap or .db3 file, or a bag folder "
            "with metadata.yaml"
        )


@contextmanager
def open_bag(path: str | Path) -> Iterator[AnyReader]:
    """Open a bag for reading (a context manager yielding rosbags' ``AnyReader``).

    Raises:
        BagError: naming the path, for anything that is not a readable bag (missing,
            another kind of file, an unfinished or damaged bag).
    """
    bag = Path(path)
    _check_path(bag)
    try:
        reader = AnyReader([bag])
        reader.open()
    except Exception as error:  # untrusted bytes: every failure of the readers is the bag's
        raise BagError(f"{bag}: damaged bag: {_reason(error)}") from None
    try:
        yield reader
    finally:
        reader.close()


def _reason(error: BaseException) -> str:
    text = " ".join(str(error).split())
    return f"{type(error).__name__}: {text}"[:300] if text else type(error).__name__


def bag_info(path: str | Path) -> BagInfo:
    """Topics, types, counts and time span of a bag.

    Raises:
        BagError: as :func:`open_bag`.
    """
    bag = Path(path)
    with open_bag(bag) as reader:
        counts: dict[tuple[str, str], int] = {}
        for connection in reader.connections:
            key = (connection.topic, connection.msgtype)
            counts[key] = counts.get(key, 0) + connection.msgcount
        topics = tuple(TopicInfo(t, m, n) for (t, m), n in sorted(counts.items()))
        messages = sum(counts.values())
        start, end = (reader.start_time, reader.end_time - 1) if messages else (0, 0)
    files = _storage_files(bag)
    suffixes = {p.suffix for p in files}
    storage = "sqlite3" if suffixes == {".db3"} else "mcap"
    return BagInfo(
        bag, storage, messages, start, end, topics, files, sum(p.stat().st_size for p in files)
    )


def _storage_files(bag: Path) -> tuple[Path, ...]:
    if bag.is_file():
        return (bag,)
    return tuple(sorted(p for p in bag.iterdir() if p.suffix in STORAGE_SUFFIXES))


def read_messages(path: str | Path, topics: Sequence[str] | None = None) -> Iterator[BagMessage]:
    """Decoded messages of a bag in log-time order, optionally of some topics only.

    Raises:
        BagError: as :func:`open_bag`, or for a topic the bag does not have, or a message
            that does not decode.
    """
    bag = Path(path)
    with open_bag(bag) as reader:
        connections = reader.connections
        if topics is not None:
            have = {c.topic for c in connections}
            if missing := [t for t in topics if t not in have]:
                raise BagError(
                    f"{bag}: no topic {', '.join(missing)}; the bag has "
                    f"{', '.join(sorted(have)) or 'no topics'}"
                )
            connections = [c for c in connections if c.topic in topics]
        messages = reader.messages(connections=connections)
        while True:
            try:
                connection, t_ns, raw = next(messages)
                message = reader.deserialize(raw, connection.msgtype)
            except StopIteration:
                return
            except Exception as error:  # untrusted bytes (a corrupt chunk, a bad message)
                raise BagError(f"{bag}: damaged bag: {_reason(error)}") from None
            yield BagMessage(connection.topic, connection.msgtype, t_ns, message)


def format_info(info: BagInfo) -> str:
    """The text ``cosim bag info`` prints: a header and a line per topic."""
    size_mb = info.size_bytes / 1e6
    lines = [
        f"bag:       {info.path}",
        f"storage:   {info.storage}, {len(info.files)} file(s), {size_mb:.2f} MB",
        f"messages:  {info.messages}",
        f"duration:  {info.duration_s:.3f} s "
        f"(from {info.start_ns / 1e9:.3f} s to {info.end_ns / 1e9:.3f} s)",
        f"topics:    {len(info.topics)}",
    ]
    if info.topics:
        width = max(len(t.name) for t in info.topics)
        type_width = max(len(t.msgtype) for t in info.topics)
        lines += [
            f"  {t.name:<{width}}  {t.msgtype:<{type_width}}  {t.count:>9}" for t in info.topics
        ]
    return "\n".join(lines)

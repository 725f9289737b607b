"""The recorder: taps the bus and collects the run's tables, events, maps and files.

Rows are kept column-wise in compact buffers during the run (integers in ``array``,
repeated strings interned as category codes), so that recording stays cheap on the hot
path; the shell turns them into DataFrames once, at the end
(:mod:`cosim.recording.dataframes`). Times are recorded in integer nanoseconds and
exported both as exact ``*_ns`` columns and as ``*_s`` seconds columns.
"""

from __future__ import annotations

from array import array
from collections.abc import Iterable, Mapping, Sequence
from typing import Any, Protocol

import numpy as np
import numpy.typing as npt

from cosim.core.hosts import HostId
from cosim.core.link import DELIVERED, Transfer
from cosim.core.table import Interner, Table, TableSpec


class MapArtifact(Protocol):
    """An occupancy map an adapter hands over for the run folder (``maps/NAME.pgm``/``.yaml``).

    Attributes:
        resolution_m: cell size (m).
        origin_xy_m: ``map`` position of the lower-left corner of cell (0, 0) (m).
        data: (rows, cols) int8 cells, row 0 at the lowest y: 0 free, 100 occupied, -1 unknown.
    """

    @property
    def resolution_m(self) -> float:
        """Cell size (m)."""
        ...

    @property
    def origin_xy_m(self) -> tuple[float, float]:
        """Lower-left corner of cell (0, 0) in ``map`` (m)."""
        ...

    @property
    def data(self) -> npt.NDArray[np.int8]:
        """The cells."""
        ...


MESSAGES = TableSpec(
    "messages",
    "One row per message and destination host: every send over the bus, its fate and size.",
    {
        "t_sent_s": "when the message was published (s)",
        "t_recv_s": "when it was delivered (s); empty when dropped",
        "src_host": "the publishing host (a robot's name, or base)",
        "dst_host": "the receiving host",
        "topic": "the topic",
        "bytes": "its size on the wire: CDR body and encapsulation header (bytes)",
        "status": "delivered, or why not: lost, queue_full, out_of_range or partitioned",
        "t_sent_ns": "t_sent_s in exact integer nanoseconds",
        "t_recv_ns": "t_recv_s in exact integer nanoseconds; empty when dropped",
    },
    categorical=("src_host", "dst_host", "topic", "status"),
    units={"bytes": "bytes"},
)
EVENTS = TableSpec(
    "events",
    "One row per discrete event any component records (goals, arrivals, tasks, contacts, ...).",
    {
        "t_s": "when (s)",
        "source": "the component that recorded it (an adapter's name)",
        "kind": "what happened, a short verb or noun (built, task, done, conflict, ...)",
        "detail": "the particulars, in words",
        "t_ns": "t_s in exact integer nanoseconds",
    },
    categorical=("source", "kind"),
)
MESSAGE_COLUMNS = tuple(MESSAGES.columns)
EVENT_COLUMNS = tuple(EVENTS.columns)


_FLUSH_ROWS = 65_536


class Recorder:
    """Collects the run's tables: messages (from the bus tap), events, and adapter tables.

    Message rows are appended column by column (a broadcast's rows in one call, see
    :meth:`on_transmission`) and packed into NumPy columns every 65,536 rows (bounded
    memory).

    Args:
        record_messages: keep a row per message and destination host.
    """

    def __init__(self, *, record_messages: bool = True) -> None:
        self.record_messages = record_messages
        self.hosts = Interner()
        self.topics = Interner()
        self.statuses = Interner()
        # the rows not packed yet, by column
        self._t_sent = array("q")
        self._t_recv = array("q")
        self._src: list[str] = []
        self._dst: list[str] = []
        self._topic: list[str] = []
        self._bytes = array("q")
        self._status: list[str] = []
        self._chunks: list[dict[str, npt.NDArray[Any]]] = []
        self.events = Table(("t_ns", "source", "kind", "detail"), name="events")
        self.tables: dict[str, Table] = {}
        self.specs: dict[str, TableSpec] = {}
        self.volatile: dict[str, tuple[str, ...]] = {}
        self.maps: dict[str, MapArtifact] = {}
        self.files: dict[str, bytes] = {}
        self.counts: dict[str, int] = {DELIVERED: 0}
        """Copies by delivery status (``delivered``, and each drop reason met)."""
        self.network_messages = 0
        self.network_bytes = 0

    # -- the bus tap ---------------------------------------------------------------
    def on_transfer(
        self,
        t_sent_ns: int,
        t_recv_ns: int | None,
        src: HostId,
        dst: HostId,
        topic: str,
        nbytes: int,
        status: str,
    ) -> None:
        """Record one message towards one destination host (see :class:`cosim.core.bus.BusTap`)."""
        self.counts[status] = self.counts.get(status, 0) + 1
        if src != dst:
            self.network_messages += 1
            self.network_bytes += nbytes
        if not self.record_messages:
            return
        self._t_sent.append(t_sent_ns)
        self._t_recv.append(-1 if t_recv_ns is None else t_recv_ns)
        self._src.append(src)
        self._dst.append(dst)
        self._topic.append(topic)
        self._bytes.append(nbytes)
        self._status.append(status)
        if len(self._src) >= _FLUSH_ROWS:
            self._flush()

    def on_transmission(
        self, t_sent_ns: int, src: HostId, topic: str, nbytes: int, transfers: Sequence[Transfer]
    ) -> None:
        """Record one transmission towards several hosts: :meth:`on_transfer` for each, in order.

        The same rows, counts and tables, appended a column at a time: a broadcast to 49
        robots is one call instead of 49.
        """
        n = len(transfers)
        if not n:
            return
        statuses = [t.status for t in transfers]
        dsts = [t.dst for t in transfers]
        counts = self.counts
        for status in statuses:
            counts[status] = counts.get(status, 0) + 1
        t_recv = [-1 if t.t_recv_ns is None else t.t_recv_ns for t in transfers]
        self._rows(t_sent_ns, src, topic, nbytes, dsts, t_recv, statuses)

    def on_all_delivered(
        self,
        t_sent_ns: int,
        src: HostId,
        topic: str,
        nbytes: int,
        dsts: Sequence[HostId],
        t_recv_ns: int,
    ) -> None:
        """Record one transmission delivered to every host in ``dsts`` at ``t_recv_ns`` (ns).

        The same rows, counts and tables as :meth:`on_transmission` with a delivered
        transfer per host, without the transfers.
        """
        n = len(dsts)
        if not n:
            return
        delivered = DELIVERED
        self.counts[delivered] += n
        self._rows(t_sent_ns, src, topic, nbytes, dsts, [t_recv_ns] * n, [delivered] * n)

    def _rows(
        self,
        t_sent_ns: int,
        src: HostId,
        topic: str,
        nbytes: int,
        dsts: Sequence[HostId],
        t_recv_ns: list[int],
        statuses: list[str],
    ) -> None:
        """Network counts and (when recording) the rows of one transmission's copies."""
        n = len(dsts)
        others = n - dsts.count(src)
        self.network_messages += others
        self.network_bytes += others * nbytes
        if not self.record_messages:
            return
        self._t_sent.extend([t_sent_ns] * n)
        self._t_recv.extend(t_recv_ns)
        self._src.extend([src] * n)
        self._dst.extend(dsts)
        self._topic.extend([topic] * n)
        self._bytes.extend([nbytes] * n)
        self._status.extend(statuses)
        if len(self._src) >= _FLUSH_ROWS:
            self._flush()

    def _flush(self, *, rest: bool = False) -> None:
        """Pack the pending rows in chunks of 65,536 rows, and with ``rest`` the rest too.

        The chunks are those of rows packed one at a time as they come, so that hosts,
        topics and statuses get their category codes in the same order (per chunk:
        sources first, then destinations).
        """
        while len(self._src) >= (1 if rest else _FLUSH_ROWS):
            take = min(len(self._src), _FLUSH_ROWS)
            hosts, topics, statuses = self.hosts, self.topics, self.statuses
            self._chunks.append(
                {
                    "t_sent": np.array(self._t_sent[:take], dtype=np.int64),
                    "t_recv": np.array(self._t_recv[:take], dtype=np.int64),
                    "src": hosts.codes_of(self._src[:take]),
                    "dst": hosts.codes_of(self._dst[:take]),
                    "topic": topics.codes_of(self._topic[:take]),
                    "bytes": np.array(self._bytes[:take], dtype=np.int64),
                    "status": statuses.codes_of(self._status[:take]),
                }
            )
            for column in (
                self._t_sent,
                self._t_recv,
                self._src,
                self._dst,
                self._topic,
                self._bytes,
                self._status,
            ):
                del column[:take]

    # -- events and adapter tables ---------------------------------------------------
    def event(self, t_ns: int, source: str, kind: str, detail: str = "") -> None:
        """Record a discrete event (``source`` is the component, ``kind`` a short verb)."""
        self.events.append(t_ns=t_ns, source=source, kind=kind, detail=detail)

    def table(
        self,
        name: str | TableSpec,
        columns: Sequence[str] = (),
        categorical: Iterable[str] = (),
        *,
        volatile: Iterable[str] = (),
    ) -> Table:
        """Create (once) and return a table; it is exported as ``tables/NAME``.

        Args:
            name: the table's :class:`TableSpec` (its columns documented), or its name.
            columns: column names, in order (with a name).
            categorical: columns of repeated strings (with a name).
            volatile: wall-clock columns (e.g. a planning time in ms): the only values
                that are not a function of the scenario and seed; comparisons of runs
                leave them out (see :attr:`volatile`). With a name.
        """
        if isinstance(name, TableSpec):
            spec = name
            self.specs[spec.name] = spec
            return self.table(
                spec.name, tuple(spec.columns), spec.categorical, volatile=spec.volatile
            )
        if name in self.tables or name in ("messages", "events"):
            raise ValueError(f"table {name!r} exists already")
        table = Table(columns, categorical, name=name)
        self.tables[name] = table
        for column in volatile:
            if column not in columns:
                raise ValueError(f"volatile column {column!r} is not a column of {name!r}")
        self.volatile[name] = tuple(volatile)
        return table

    def add_map(self, name: str, grid: MapArtifact) -> None:
        """Keep a final map for the run folder (``maps/NAME``)."""
        if name in self.maps:
            raise ValueError(f"map {name!r} exists already")
        self.maps[name] = grid

    def add_file(self, relative: str, data: bytes) -> None:
        """Keep a file for the run folder, at ``relative`` (e.g. ``sumo/aisles.net.xml``)."""
        if relative in self.files:
            raise ValueError(f"file {relative!r} exists already")
        self.files[relative] = data

    # -- export ----------------------------------------------------------------------
    def message_columns(self) -> dict[str, npt.NDArray[Any]]:
        """The messages table's raw columns, one row per message and destination host.

        ``t_sent`` and ``t_recv`` (ns; -1 when not delivered), ``bytes``, and the codes
        of ``src`` and ``dst`` (in :attr:`hosts`), ``topic`` (in :attr:`topics`) and
        ``status`` (in :attr:`statuses`).
        """
        self._flush(rest=True)
        empty = {"t_sent": np.int64, "t_recv": np.int64, "bytes": np.int64}
        columns: dict[str, npt.NDArray[Any]] = {}
        for name in ("t_sent", "t_recv", "src", "dst", "topic", "bytes", "status"):
            parts = [chunk[name] for chunk in self._chunks]
            columns[name] = (
                np.concatenate(parts) if parts else np.zeros(0, dtype=empty.get(name, np.int32))
            )
        return columns


def merge_counts(into: dict[str, Any], extra: Mapping[str, Any]) -> None:
    """Merge summary entries, refusing to overwrite an existing key."""
    for key, value in extra.items():
        if key in into:
            raise ValueError(f"summary key {key!r} reported twice")
        into[key] = value

"""A run's tables as pandas DataFrames: from the recorder's NumPy columns, once, at the end.

Repeated strings become ``category`` columns; the messages table gets its seconds columns
from the exact nanoseconds and a nullable ``t_recv_ns`` (empty when a copy was dropped);
the events table its ``t_s``.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pandas as pd

from cosim.core.recorder import EVENTS, MESSAGES, Recorder
from cosim.core.table import Interner, Table
from cosim.core.timebase import NS_PER_S


def table_frame(table: Table) -> pd.DataFrame:
    """One table's rows as a DataFrame, its categorical columns as ``category``."""
    columns: dict[str, Any] = {}
    for name, values in table.columns().items():
        columns[name] = pd.Categorical(values) if name in table.categorical else values
    return pd.DataFrame(columns, columns=table.names)


def _categorical(strings: Interner, codes: np.ndarray[Any, Any]) -> pd.Categorical[str]:
    return pd.Categorical.from_codes(codes, categories=pd.Index(strings.values))


def messages_frame(recorder: Recorder) -> pd.DataFrame:
    """The messages table: one row per message and destination host."""
    raw = recorder.message_columns()
    t_sent, t_recv = raw["t_sent"], raw["t_recv"]
    received = t_recv >= 0
    return pd.DataFrame(
        {
            "t_sent_s": t_sent / NS_PER_S,
            "t_recv_s": np.where(received, t_recv / NS_PER_S, math.nan),
            "src_host": _categorical(recorder.hosts, raw["src"]),
            "dst_host": _categorical(recorder.hosts, raw["dst"]),
            "topic": _categorical(recorder.topics, raw["topic"]),
            "bytes": raw["bytes"],
            "status": _categorical(recorder.statuses, raw["status"]),
            "t_sent_ns": t_sent,
            "t_recv_ns": pd.arrays.IntegerArray(np.where(received, t_recv, 0), ~received),
        },
        columns=list(MESSAGES.columns),
    )


def events_frame(recorder: Recorder) -> pd.DataFrame:
    """The events table (t_s, source, kind, detail, t_ns)."""
    frame = table_frame(recorder.events)
    t_ns = frame["t_ns"].to_numpy(dtype=np.int64)
    frame = frame.assign(t_s=t_ns / NS_PER_S, t_ns=t_ns)
    for column in ("source", "kind"):
        frame[column] = frame[column].astype("category")
    frame["detail"] = frame["detail"].astype(str)
    return frame[list(EVENTS.columns)]


def run_frames(recorder: Recorder) -> dict[str, pd.DataFrame]:
    """Every table of a run as a DataFrame, keyed by table name."""
    frames = {"messages": messages_frame(recorder), "events": events_frame(recorder)}
    for name, table in recorder.tables.items():
        frames[name] = table_frame(table)
    return frames

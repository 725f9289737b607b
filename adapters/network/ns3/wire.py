"""What the run and its radio process say to each other: records and frames.

Nothing here imports ns-3: the run's process reads the radio's records with these
layouts, the radio's process (:mod:`adapters.network.ns3.child`) writes them.

Frames on the pipes are a little-endian ``u32`` length and a pickle (protocol 5): requests
``(command, argument)``, answers ``("ok", result)`` or ``("err", kind, text)``.
"""

from __future__ import annotations

import pickle
import struct
from typing import IO, Any

import numpy as np

RX_DTYPE = np.dtype(
    [
        ("t_ns", "<i8"),
        ("msg_id", "<i8"),
        ("rx", "<i4"),
        ("tx", "<i4"),
        ("rssi_dbm", "<f8"),
        ("snr_db", "<f8"),
    ]
)
"""A reception: when (ns), the message id, receiving and sending node, signal (dBm) and
signal over noise and interference (dB) of the frame as the receiver's PHY saw it (the last
fragment's, for a fragmented message; NaN when not seen)."""

DROP_DTYPE = np.dtype(
    [
        ("t_ns", "<i8"),
        ("msg_id", "<i8"),
        ("rx", "<i4"),
        ("tx", "<i4"),
        ("reason", "<i4"),
        ("frag", "<i4"),
    ]
)
"""A frame a PHY dropped: when (ns), the message id (-1 unless the frame is a message's
first fragment), the node that dropped it, the sender (-1 unknown), ns-3's
``WifiPhyRxfailureReason`` and the IP fragment offset (bytes; -1 not IP)."""

_LENGTH = struct.Struct("<I")


def write_frame(out: IO[bytes], obj: Any) -> None:
    """Write one frame and flush."""
    data = pickle.dumps(obj, protocol=5)
    out.write(_LENGTH.pack(len(data)))
    out.write(data)
    out.flush()


def read_frame(inp: IO[bytes]) -> Any:
    """Read one frame.

    Raises:
        EOFError: the other end closed the pipe.
    """
    (n,) = _LENGTH.unpack(_read_exactly(inp, 4))
    return pickle.loads(_read_exactly(inp, n))


def _read_exactly(inp: IO[bytes], n: int) -> bytes:
    buf = bytearray()
    while len(buf) < n:
        chunk = inp.read(n - len(buf))
        if not chunk:
            raise EOFError("the pipe closed")
        buf += chunk
    return bytes(buf)

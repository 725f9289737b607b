"""Tables a run records, kept column-wise in NumPy arrays while the run goes.

A table is filled row by row (:meth:`Table.append`) or in column batches
(:meth:`Table.extend`); its columns come back as NumPy arrays (:meth:`Table.columns`). The
shell turns them into pandas DataFrames and parquet files when the run ends
(:mod:`cosim.recording.dataframes`), so that the core, and the adapters on it, need no
pandas. Times are in integer nanoseconds in the kernel and in seconds in the tables'
``*_s`` columns.

What is written must match the table's columns: a row or a batch with a column the table
does not have, without one it has, or with columns of different lengths is refused
(:class:`~cosim.core.plugins.PluginError` naming the table and the column; the runner names
the plugin from the calling frames), and nothing of it is kept. The check is one length
comparison per row, one key comparison per batch.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt

from cosim.core.plugins import PluginError
from cosim.core.timebase import NS_PER_S


@dataclass(frozen=True)
class TableSpec:
    """A table a run writes (``tables/NAME.parquet``), with what each column means.

    Every table is declared once, with its columns' meanings, so that the documentation's
    table reference is generated from the code that writes the tables. Units are in the
    column names (``t_s``, ``x_m``, ``yaw_rad``, ``bytes``); positions are in ``map``.

    Attributes:
        name: the table's name.
        doc: one line: what a row is.
        columns: column -> its meaning, in output order.
        categorical: columns of repeated strings (written as ``category``).
        volatile: wall-clock columns: the only values that are not a function of the
            scenario and seed (comparisons of runs leave them out).
        units: the unit of a numeric column whose name cannot carry it (``bytes`` in
            bytes, ``cost`` in m), or what a unitless one is (``count``, ``fraction``);
            the table reference shows it, or else the unit the name carries.
    """

    name: str
    doc: str
    columns: Mapping[str, str]
    categorical: tuple[str, ...] = ()
    volatile: tuple[str, ...] = ()
    units: Mapping[str, str] = field(default_factory=dict)


class Interner:
    """Maps repeated strings to small integer codes, in order of first appearance.

    Attributes:
        values: the distinct strings, the code of each being its index.
    """

    def __init__(self) -> None:
        self._codes: dict[str, int] = {}
        self.values: list[str] = []

    def code(self, value: str) -> int:
        """The code of ``value`` (a new one for a new string)."""
        code = self._codes.get(value)
        if code is None:
            code = len(self.values)
            self._codes[value] = code
            self.values.append(value)
        return code

    def codes_of(self, values: Sequence[str]) -> npt.NDArray[np.int32]:
        """The codes of ``values``, new values coded in order of first appearance.

        A ``str`` subclass (a ``StrEnum`` member) is coded as its plain string value.
        """
        for value in dict.fromkeys(values):  # the distinct values, in order
            self.code(str(value))
        return np.fromiter(map(self._codes.__getitem__, values), np.int32, len(values))


class Table:
    """A table filled row by row or in column batches, rows kept in append order.

    Args:
        columns: column names in output order.
        categorical: columns holding repeated strings (exported as ``category``).
        name: the table's name, for errors.
    """

    def __init__(
        self, columns: Sequence[str], categorical: Iterable[str] = (), *, name: str = ""
    ) -> None:
        if not columns:
            raise ValueError("a table needs at least one column")
        self.name = name
        self.names = list(columns)
        self._keys = frozenset(self.names)
        self.categorical = frozenset(categorical)
        self._rows: dict[str, list[Any]] = {name: [] for name in self.names}
        self._chunks: list[dict[str, npt.NDArray[Any]]] = []
        self._length = 0

    def append(self, **row: Any) -> None:
        """Add one row; every column must be given, and no other.

        Raises:
            PluginError: a column missing or unknown (nothing is added).
        """
        if len(row) != len(self.names):
            raise self._mismatch("a row", row.keys())
        rows = self._rows
        try:
            for name in self.names:
                rows[name].append(row[name])
        except KeyError:  # as many keys, one of them unknown: undo what was appended
            for name in self.names:
                if name not in row:
                    break
                rows[name].pop()
            raise self._mismatch("a row", row.keys()) from None
        self._length += 1

    def extend(self, **columns: Any) -> None:
        """Add rows from equal-length arrays; scalars are repeated to that length.

        Raises:
            PluginError: a column missing or unknown, or columns of different lengths
                (nothing is added).
        """
        if columns.keys() != self._keys:
            raise self._mismatch("rows", columns.keys())
        self._flush_rows()
        arrays = {name: np.asarray(columns[name]) for name in self.names}
        length = max((a.shape[0] for a in arrays.values() if a.ndim), default=1)
        for name, values in arrays.items():
            if values.ndim == 0:
                arrays[name] = np.full(length, values.item())
            elif values.shape[0] != length:
                longest = next(n for n, a in arrays.items() if a.ndim and a.shape[0] == length)
                raise PluginError(
                    None,
                    f"wrote rows to table {self.name!r} with {values.shape[0]} values in column "
                    f"{name!r} and {length} in {longest!r}; expected columns of one length "
                    "(or a single value, repeated)",
                    doing=f"recording table {self.name!r}",
                )
        self._chunks.append(arrays)
        self._length += length

    def _mismatch(self, what: str, given: Iterable[str]) -> PluginError:
        """The error for ``what`` (a row, rows) written with the columns ``given``."""
        given = list(given)
        unknown = [name for name in given if name not in self._keys]
        missing = [name for name in self.names if name not in given]
        found = []
        if unknown:
            found.append(f"unknown column{'s' * (len(unknown) > 1)} {_listed(unknown)}")
        if missing:
            found.append(f"no column {_listed(missing)}")
        return PluginError(
            None,
            f"wrote {what} to table {self.name!r} with {' and '.join(found)}; expected the "
            f"columns of its TableSpec: {', '.join(self.names)}",
            doing=f"recording table {self.name!r}",
        )

    def _flush_rows(self) -> None:
        if self._rows[self.names[0]]:
            self._chunks.append({name: np.asarray(v) for name, v in self._rows.items()})
            self._rows = {name: [] for name in self.names}

    def __len__(self) -> int:
        return self._length

    def column(self, name: str) -> npt.NDArray[Any]:
        """One column's values, in row order (an empty float array for no rows)."""
        self._flush_rows()
        chunks = [chunk[name] for chunk in self._chunks]
        return np.concatenate(chunks) if chunks else np.array([], dtype=float)

    def columns(self) -> dict[str, npt.NDArray[Any]]:
        """Every column's values, in output order."""
        return {name: self.column(name) for name in self.names}


def _listed(names: list[str]) -> str:
    return ", ".join(repr(name) for name in names)


def ns_column(values: npt.ArrayLike) -> npt.NDArray[np.float64]:
    """Convert an array of integer nanoseconds to float seconds."""
    return np.asarray(values, dtype=np.int64) / NS_PER_S

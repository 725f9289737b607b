"""Tables kept column-wise while a run goes: rows in append order, strings coded."""

import dataclasses
from enum import StrEnum

import numpy as np
import pytest

from cosim.core.table import Interner, Table, TableSpec, ns_column


def test_a_table_without_columns_is_refused():
    with pytest.raises(ValueError, match="at least one column"):
        Table(())


def test_rows_appended_come_back_column_by_column_in_order():
    table = Table(("t_ns", "robot", "x_m"), categorical=("robot",))
    table.append(t_ns=1, robot="robot_1", x_m=0.5)
    table.append(x_m=1.5, robot="robot_2", t_ns=2)  # keyword order does not matter
    columns = table.columns()
    assert list(columns) == ["t_ns", "robot", "x_m"]
    assert columns["t_ns"].tolist() == [1, 2]
    assert columns["robot"].tolist() == ["robot_1", "robot_2"]
    assert columns["x_m"].dtype == np.float64
    assert len(table) == 2 and table.categorical == frozenset({"robot"})


def test_a_row_missing_a_column_is_refused_naming_it():
    table = Table(("a", "b"))
    with pytest.raises(KeyError, match="b"):
        table.append(a=1)


def test_column_batches_and_rows_keep_their_order_and_scalars_repeat():
    table = Table(("t_ns", "robot", "v"))
    table.append(t_ns=0, robot="a", v=0.0)
    table.extend(t_ns=np.array([1, 2, 3]), robot="b", v=[1.0, 2.0, 3.0])
    table.append(t_ns=4, robot="c", v=4.0)
    assert table.column("t_ns").tolist() == [0, 1, 2, 3, 4]
    assert table.column("robot").tolist() == ["a", "b", "b", "b", "c"]
    assert len(table) == 5


def test_a_batch_of_scalars_alone_is_one_row():
    table = Table(("a", "b"))
    table.extend(a=1, b="x")
    assert len(table) == 1
    assert table.column("a").tolist() == [1] and table.column("b").tolist() == ["x"]


def test_a_batch_with_columns_of_different_lengths_is_refused_naming_the_column():
    table = Table(("a", "b"))
    with pytest.raises(ValueError, match=r"column 'b' has 2 rows, expected 3"):
        table.extend(a=[1, 2, 3], b=[1, 2])
    assert len(table) == 0


def test_an_empty_column_is_an_empty_float_array():
    column = Table(("a",)).column("a")
    assert column.shape == (0,) and column.dtype == np.float64


def test_strings_are_coded_in_order_of_first_appearance():
    interner = Interner()
    codes = interner.codes_of(["b", "a", "b", "c", "a"])
    assert codes.tolist() == [0, 1, 0, 2, 1] and codes.dtype == np.int32
    assert interner.code("a") == 1 and interner.code("d") == 3
    assert interner.values == ["b", "a", "c", "d"]
    assert interner.codes_of([]).tolist() == []


class Status(StrEnum):
    LOST = "lost"


def test_a_str_enum_member_is_coded_as_its_plain_string():
    interner = Interner()
    assert interner.codes_of([Status.LOST, "lost"]).tolist() == [0, 0]
    assert type(interner.values[0]) is str


def test_integer_nanoseconds_become_float_seconds():
    seconds = ns_column([0, 1_500_000_000, 2**62])
    assert seconds.dtype == np.float64
    assert seconds.tolist() == [0.0, 1.5, 2**62 / 1e9]


def test_a_table_spec_is_immutable_with_no_categorical_or_volatile_columns_by_default():
    spec = TableSpec("poses", "One row per robot and sample.", {"t_s": "when (s)", "x_m": "x (m)"})
    assert (spec.categorical, spec.volatile) == ((), ())
    assert list(spec.columns) == ["t_s", "x_m"]
    with pytest.raises(dataclasses.FrozenInstanceError):
        spec.name = "other"  # type: ignore[misc]

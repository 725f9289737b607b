"""Tables kept column-wise while a run goes: rows in append order, strings coded."""

import dataclasses
import re
from enum import StrEnum

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cosim.core.plugins import PluginError
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


def test_a_row_missing_a_column_is_refused_naming_the_table_and_the_column():
    table = Table(("a", "b"), name="battery")
    with pytest.raises(PluginError) as caught:
        table.append(a=1)
    assert str(caught.value) == (
        "a plugin wrote a row to table 'battery' with no column 'b'; expected the columns of "
        "its TableSpec: a, b while recording table 'battery'"
    )
    assert caught.value.plugin is None  # the runner names it from the calling frames
    assert len(table) == 0


@pytest.mark.parametrize(
    ("row", "said"),
    [
        ({"a": 1, "b": 2, "c": 3}, "with unknown column 'c'; expected"),
        ({"a": 1, "c": 3}, "with unknown column 'c' and no column 'b'; expected"),
        ({"c": 3, "d": 4}, "with unknown columns 'c', 'd' and no column 'a', 'b'; expected"),
    ],
)
def test_a_row_with_a_column_the_table_does_not_have_is_refused_and_nothing_kept(row, said):
    table = Table(("a", "b"), name="battery")
    table.append(a=0, b=0)
    with pytest.raises(PluginError, match=re.escape(f"a row to table 'battery' {said}")):
        table.append(**row)
    assert {k: v.tolist() for k, v in table.columns().items()} == {"a": [0], "b": [0]}
    table.append(a=5, b=6)  # the table is whole: the next row lines up
    assert {k: v.tolist() for k, v in table.columns().items()} == {"a": [0, 5], "b": [0, 6]}


@settings(max_examples=60, deadline=None)
@given(st.dictionaries(st.sampled_from(["a", "b", "c", "t_s"]), st.integers(), max_size=4))
def test_any_row_is_kept_whole_or_refused_whole(row):
    table = Table(("t_s", "a", "b"), name="t")
    try:
        table.append(**row)
    except PluginError:
        assert set(row) != {"t_s", "a", "b"}
        assert [len(v) for v in table.columns().values()] == [0, 0, 0]
    else:
        assert set(row) == {"t_s", "a", "b"}
        assert [v.tolist() for v in table.columns().values()] == [
            [row["t_s"]],
            [row["a"]],
            [row["b"]],
        ]


def test_a_batch_with_an_unknown_or_missing_column_is_refused_naming_them():
    table = Table(("t_s", "robot", "charge_wh"), name="battery")
    with pytest.raises(PluginError) as caught:
        table.extend(t_s=[0.0, 1.0], robot=["a", "b"], charge=[1.0, 2.0])
    assert str(caught.value) == (
        "a plugin wrote rows to table 'battery' with unknown column 'charge' and no column "
        "'charge_wh'; expected the columns of its TableSpec: t_s, robot, charge_wh while "
        "recording table 'battery'"
    )
    assert len(table) == 0


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


def test_a_batch_with_columns_of_different_lengths_is_refused_naming_the_columns():
    table = Table(("a", "b"), name="battery")
    with pytest.raises(PluginError) as caught:
        table.extend(a=[1, 2, 3], b=[1, 2])
    assert str(caught.value) == (
        "a plugin wrote rows to table 'battery' with 2 values in column 'b' and 3 in 'a'; "
        "expected columns of one length (or a single value, repeated) while recording table "
        "'battery'"
    )
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


def test_a_table_spec_declares_the_units_its_column_names_cannot_carry():
    spec = TableSpec("t", "one row", {"t_s": "when (s)", "bytes": "size"}, units={"bytes": "bytes"})
    assert spec.units == {"bytes": "bytes"}
    assert TableSpec("t", "one row", {"t_s": "when (s)"}).units == {}

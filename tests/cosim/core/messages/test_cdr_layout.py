"""A message's layout: the flat list of what is written, from its type and its sources."""

import itertools

import pytest

from cosim.core.errors import WireError
from cosim.core.messages import std
from cosim.core.messages.cdr_layout import (
    AsTuple,
    Expr,
    Fields,
    Items,
    Let,
    Loop,
    Prim,
    Seq,
    TimeOp,
    Txt,
    fixed_body,
    flatten,
    literal,
    needs,
)
from cosim.core.messages.wire import (
    FLOAT32,
    FLOAT64,
    INT32,
    STRING,
    UINT8,
    UINT32,
    Array,
    Sequence,
)


def _names():
    counter = itertools.count(1)
    return lambda prefix: f"_{prefix}{next(counter)}"


def test_a_struct_from_fields_writes_each_field_in_order_and_unnamed_ones_as_zero():
    ops = flatten(std.POINT, Fields({"y": Expr("m.y_m")}), _names())
    assert ops == [Prim(FLOAT64, None), Prim(FLOAT64, "m.y_m"), Prim(FLOAT64, None)]


def test_a_struct_from_a_tuple_reads_its_fields_by_position_nested_the_same_way():
    ops = flatten(std.POSE, AsTuple("m.pose"), _names())
    assert ops == [
        *(Prim(FLOAT64, f"m.pose[0][{i}]") for i in range(3)),
        *(Prim(FLOAT64, f"m.pose[1][{i}]") for i in range(4)),
    ]


def test_a_time_is_one_operation_of_integer_ns_with_its_two_fields_types():
    ops = flatten(std.HEADER, Fields({"stamp": Expr("m.t")}), _names())
    assert ops == [TimeOp("m.t", std.TIME.fields[0][1], UINT32), Txt(None)]  # type: ignore[arg-type]
    assert flatten(std.CLOCK, None, _names()) == [TimeOp(None, INT32, UINT32)]


def test_a_type_left_unbound_is_written_as_zeros_and_empty_sequences():
    ops = flatten(std.PATH, None, _names())
    assert ops == [TimeOp(None, INT32, UINT32), Txt(None), Prim(UINT32, "0")]


def test_a_fixed_array_of_primitives_spreads_its_value_and_has_no_count():
    kind = std.POSE_WITH_COVARIANCE
    ops = flatten(kind, Fields({"covariance": Expr("m.cov")}), _names())
    assert ops[-1] == Prim(FLOAT64, "*m.cov", 36)
    assert flatten(Array(FLOAT32, 4), None, _names()) == [Prim(FLOAT32, None, 4)]


def test_a_fixed_array_of_structs_holds_its_value_once_and_writes_each_element():
    ops = flatten(Array(std.POINT, 2), Expr("m.corners"), _names())
    assert ops[0] == Let("_a1", "m.corners")
    assert ops[1:4] == [Prim(FLOAT64, f"_a1[0][{i}]") for i in range(3)]
    assert ops[4:] == [Prim(FLOAT64, f"_a1[1][{i}]") for i in range(3)]


def test_a_sequence_of_primitives_is_its_count_and_elements_in_one_operation():
    assert flatten(Sequence(FLOAT32), Expr("m.r"), _names()) == [Seq(FLOAT32, "m.r")]


def test_a_sequence_of_structs_from_items_loops_over_the_element_source():
    element = Fields({"x": Expr("p.x")})
    ops = flatten(Sequence(std.POINT), Items("m.points", "p", element), _names())
    assert ops == [
        Loop("m.points", "p", [Prim(FLOAT64, "p.x"), Prim(FLOAT64, None), Prim(FLOAT64, None)])
    ]


def test_a_sequence_of_structs_from_an_expression_loops_over_tuples():
    (loop,) = flatten(Sequence(std.POINT), Expr("m.points"), _names())
    assert isinstance(loop, Loop) and loop.iterable == "m.points"
    assert loop.body == [Prim(FLOAT64, f"{loop.var}[{i}]") for i in range(3)]
    (strings,) = flatten(Sequence(STRING), Expr("m.names"), _names())
    assert isinstance(strings, Loop) and strings.body == [Txt(strings.var)]


def test_a_struct_given_a_single_value_is_refused_naming_its_type():
    with pytest.raises(WireError, match=r"geometry_msgs/msg/Point: fields or a tuple expected"):
        flatten(std.POINT, Expr("m.p"), _names())


def test_a_primitive_given_fields_is_refused():
    with pytest.raises(WireError, match="a single value expected"):
        flatten(FLOAT64, Fields({}), _names())


@pytest.mark.parametrize(
    ("code", "known"),
    [(None, b""), ("'map'", b"map"), ("'é'", "é".encode()), ("m.frame", None), ("3", None)],
)
def test_a_string_is_known_in_advance_only_when_unset_or_a_constant(code, known):
    assert literal(code) == known


def test_what_follows_needs_the_alignment_of_its_first_bytes():
    assert needs(None) == 1
    assert needs(Let("x", "1")) == 1
    assert needs(Prim(FLOAT64, None)) == 8
    assert needs(Prim(UINT8, None)) == 1
    assert needs(Txt(None)) == needs(Seq(INT32, "x")) == 4


def test_a_loop_body_of_primitives_alone_has_a_fixed_layout():
    assert fixed_body([Prim(FLOAT64, "p.x"), Prim(UINT8, None)])
    assert not fixed_body([Prim(FLOAT64, "p.x"), Txt("p.name")])
    assert not fixed_body([Prim(FLOAT64, "*p.cov", 36)])

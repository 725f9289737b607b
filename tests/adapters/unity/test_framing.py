"""The ROS-TCP-Endpoint wire format: frames written, frames read, and what is refused."""

from __future__ import annotations

import json
import socket
import struct

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from adapters.unity.framing import (
    KEEPALIVE,
    MAX_COMMAND_BYTES,
    MAX_DESTINATION_BYTES,
    MAX_JSON_DEPTH,
    MAX_PAYLOAD_BYTES,
    VERSION,
    FrameError,
    command,
    error,
    frame,
    handshake,
    json_depth,
    parse_json,
    read_frame,
    text_field,
)

U32 = struct.Struct("<I")


class Stream:
    """A socket's receiving end over given bytes, handing out at most ``chunk`` at a time."""

    def __init__(self, data: bytes, chunk: int = 1 << 30) -> None:
        self.data = data
        self.chunk = chunk

    def recv_into(self, view: memoryview, size: int) -> int:
        n = min(size, self.chunk, len(self.data))
        view[:n] = self.data[:n]
        self.data = self.data[n:]
        return n


def _read_all(data: bytes, chunk: int = 1 << 30) -> list[tuple[str, bytes]]:
    stream = Stream(data, chunk)
    got = []
    while (one := read_frame(stream)) is not None:  # type: ignore[arg-type]
        got.append(one)
    return got


def test_a_frame_is_the_destination_and_the_payload_each_behind_its_u32_le_length():
    assert frame("/robot_1/scan", b"\x00\x01\x00\x00abc") == (
        b"\x0d\x00\x00\x00/robot_1/scan\x07\x00\x00\x00\x00\x01\x00\x00abc"
    )
    assert frame("é", b"") == b"\x02\x00\x00\x00\xc3\xa9\x00\x00\x00\x00"  # UTF-8 bytes counted


def test_a_keepalive_is_eight_zero_bytes_read_as_an_empty_frame():
    assert KEEPALIVE == frame("", b"") == bytes(8)
    assert _read_all(KEEPALIVE) == [("", b"")]


def test_the_handshake_names_version_0_7_and_the_ros2_protocol():
    [(destination, payload)] = _read_all(handshake())
    params = json.loads(payload)
    assert destination == "__handshake"
    assert params["version"] == VERSION and VERSION.startswith("v0.7")
    assert json.loads(params["metadata"]) == {"protocol": "ROS2"}


def test_an_error_frame_carries_the_text_for_unitys_console():
    [(destination, payload)] = _read_all(error("cosim: no such topic"))
    assert destination == "__error"
    assert json.loads(payload) == {"text": "cosim: no such topic"}


def test_the_connectors_trailing_nul_is_stripped_from_the_destination_not_the_payload():
    name = b"/robot_1/goal_pose\x00"
    data = U32.pack(len(name)) + name + U32.pack(3) + b"ab\x00"
    assert _read_all(data) == [("/robot_1/goal_pose", b"ab\x00")]


def test_frames_split_over_many_reads_come_whole_and_in_order():
    data = frame("/a", b"1" * 50) + KEEPALIVE + command("__topic_list", {})
    assert _read_all(data, chunk=3) == [("/a", b"1" * 50), ("", b""), ("__topic_list", b"{}")]


def test_a_clean_close_between_frames_is_the_end_of_the_stream():
    assert read_frame(Stream(b"")) is None  # type: ignore[arg-type]


@pytest.mark.parametrize(
    ("data", "says"),
    [
        (b"\x05\x00", "connection closed 2 bytes into a 4-byte field"),
        (U32.pack(5) + b"/ab", "connection closed 3 bytes into a 5-byte field"),
        (U32.pack(2) + b"/a", "connection closed before the payload length"),
        (U32.pack(2) + b"/a" + U32.pack(9) + b"abc", "3 bytes into a 9-byte field"),
    ],
)
def test_a_close_in_the_middle_of_a_frame_is_a_frame_error_saying_where(data, says):
    with pytest.raises(FrameError, match=says):
        _read_all(data)


def test_a_destination_longer_than_allowed_is_refused_before_it_is_read():
    data = U32.pack(MAX_DESTINATION_BYTES + 1)
    with pytest.raises(FrameError, match=r"destination of 1025 bytes; expected at most 1024"):
        _read_all(data)


def test_a_payload_larger_than_16_mib_is_refused_before_it_is_read():
    data = U32.pack(2) + b"/a" + U32.pack(MAX_PAYLOAD_BYTES + 1)
    with pytest.raises(FrameError, match=rf"payload of {MAX_PAYLOAD_BYTES + 1} bytes; expected"):
        _read_all(data)


def test_a_destination_that_is_not_utf8_is_refused():
    data = U32.pack(2) + b"\xff\xfe" + U32.pack(0)
    with pytest.raises(FrameError, match="is not UTF-8"):
        _read_all(data)


def test_frames_cross_a_real_socket():
    left, right = socket.socketpair()
    with left, right:
        left.sendall(frame("/x", b"payload") + KEEPALIVE)
        left.shutdown(socket.SHUT_WR)
        assert read_frame(right) == ("/x", b"payload")
        assert read_frame(right) == ("", b"")
        assert read_frame(right) is None


def test_a_commands_json_is_read_with_its_trailing_nul_and_empty_means_no_parameters():
    assert parse_json("__subscribe", b'{"topic": "/a"}\x00') == {"topic": "/a"}
    assert parse_json("__topic_list", b"") == {}
    assert parse_json("__topic_list", b"\x00") == {}


@pytest.mark.parametrize(
    ("payload", "says"),
    [
        (b"{topic", r"__subscribe: the payload is not JSON \("),
        (b"\xff\xfe", r"__subscribe: the payload is not JSON \("),
        (b'["/a"]', "__subscribe: expected a JSON object, got list"),
        (b"3", "__subscribe: expected a JSON object, got int"),
    ],
)
def test_a_payload_that_is_no_json_object_is_refused_naming_the_command(payload, says):
    with pytest.raises(ValueError, match=says):
        parse_json("__subscribe", payload)


@pytest.mark.parametrize("params", [{}, {"topic": ""}, {"topic": 3}, {"topic": None}])
def test_a_missing_or_empty_text_field_is_refused_naming_the_command_and_key(params):
    with pytest.raises(ValueError) as refused:
        text_field(params, "topic", "__publish")
    message = str(refused.value)
    assert message.startswith("__publish: 'topic' is ")
    assert message.endswith("expected a non-empty string")


def test_a_text_field_is_given_as_it_is():
    assert text_field({"topic": "/robot_1/goal_pose"}, "topic", "__publish") == "/robot_1/goal_pose"


DESTINATIONS = st.text(max_size=60).filter(lambda s: not s.endswith("\x00"))


@settings(max_examples=200, deadline=None)
@given(
    st.lists(st.tuples(DESTINATIONS, st.binary(max_size=200)), max_size=5),
    st.integers(1, 16),
)
def test_any_frames_written_are_read_back_the_same_however_the_bytes_arrive(frames, chunk):
    data = b"".join(frame(d, p) for d, p in frames)
    assert _read_all(data, chunk) == frames


@settings(max_examples=300, deadline=None)
@given(st.binary(max_size=80), st.integers(1, 9))
def test_any_bytes_are_read_as_frames_or_refused_as_a_frame_error_in_one_line(data, chunk):
    try:
        got = _read_all(data, chunk)
    except FrameError as problem:
        assert "\n" not in str(problem)
        return
    assert sum(8 + len(d.encode()) + len(p) for d, p in got) <= len(data)


@settings(max_examples=200, deadline=None)
@given(st.binary(max_size=40))
def test_any_command_payload_is_a_json_object_or_refused_with_a_value_error(payload):
    try:
        value = parse_json("__publish", payload)
    except ValueError as problem:
        assert str(problem).startswith("__publish: ")
        return
    assert isinstance(value, dict)


@pytest.mark.parametrize(
    ("text", "depth"),
    [
        (b'{"topic": "/a", "message_name": "std_msgs/String"}', 1),
        (b"3", 0),
        (b'{"a": [1, {"b": "[[[{{{"}]}', 3),
        (b'["a\\"]", "]]"]', 1),  # an escaped quote does not end the string
        (b"[" * 5000, 5000),  # unbalanced: counted as it opens
        (b'["unterminated [[[', 1),  # a string running to the end hides its brackets
        (b"", 0),
    ],
)
def test_the_depth_of_json_counts_arrays_and_objects_not_brackets_in_strings(text, depth):
    assert json_depth(text) == depth


def test_json_nested_deeper_than_allowed_is_refused_naming_the_command_and_the_depth():
    deep = b'{"topic": ' * 40 + b'"/a"' + b"}" * 40
    with pytest.raises(ValueError) as refused:
        parse_json("__subscribe", deep)
    assert str(refused.value) == (
        f"__subscribe: JSON nested 40 levels deep; expected at most {MAX_JSON_DEPTH} "
        "(a command is a flat object)"
    )
    deepest = b'{"a": ' * MAX_JSON_DEPTH + b"1" + b"}" * MAX_JSON_DEPTH + b"\x00"
    assert json_depth(deepest) == MAX_JSON_DEPTH and "a" in parse_json("__publish", deepest)


def test_json_deep_enough_to_exhaust_pythons_parser_is_refused_as_too_deep():
    with pytest.raises(RecursionError):  # what the reader thread died of
        json.loads("[" * 30_000 + "]" * 30_000)
    with pytest.raises(ValueError, match=r"^__subscribe: JSON nested 30000 levels deep; "):
        parse_json("__subscribe", b"[" * 30_000 + b"]" * 30_000)


def test_a_command_larger_than_allowed_is_refused_naming_its_size():
    big = json.dumps({"topic": "/a" * MAX_COMMAND_BYTES}).encode()
    with pytest.raises(ValueError) as refused:
        parse_json("__publish", big)
    assert str(refused.value) == (
        f"__publish: a JSON payload of {len(big)} bytes; expected at most {MAX_COMMAND_BYTES} "
        "(a command is a small flat object)"
    )


def test_a_number_too_long_for_python_is_refused_as_not_json_in_one_line():
    with pytest.raises(ValueError, match=r"^__subscribe: the payload is not JSON \(") as refused:
        parse_json("__subscribe", b'{"queue_size": ' + b"9" * 5000 + b"}")
    assert "\n" not in str(refused.value)


JSON_VALUES = st.recursive(
    st.none() | st.booleans() | st.integers() | st.floats() | st.text(max_size=10),
    lambda inner: st.lists(inner, max_size=3) | st.dictionaries(st.text(max_size=5), inner),
    max_leaves=30,
)
DEEP_JSON = st.builds(
    lambda depth, opener, closed: opener * depth + (b"]" * depth if closed else b""),
    st.integers(1, 20_000),
    st.sampled_from([b"[", b'{"a":', b'[{"b": "]"}, ']),
    st.booleans(),
)


@settings(max_examples=300, deadline=None)
@given(st.one_of(JSON_VALUES.map(lambda v: json.dumps(v).encode()), DEEP_JSON, st.binary()))
def test_any_json_or_bytes_is_a_command_object_or_refused_in_one_line_naming_the_command(payload):
    try:
        value = parse_json("__subscribe", payload)
    except ValueError as problem:
        assert str(problem).startswith("__subscribe: ") and "\n" not in str(problem)
        return
    assert isinstance(value, dict) and json_depth(payload) <= MAX_JSON_DEPTH

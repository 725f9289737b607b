import io

import numpy as np
import pytest

from adapters.network.ns3.wire import DROP_DTYPE, RX_DTYPE, read_frame, write_frame


def test_a_frame_comes_back_as_it_was_written_arrays_included():
    pipe = io.BytesIO()
    rx = np.zeros(3, dtype=RX_DTYPE)
    rx["msg_id"] = [4, 5, 6]
    write_frame(pipe, ("step", {"until": 10, "rx": rx.tobytes()}))
    write_frame(pipe, ("exit", None))
    pipe.seek(0)
    command, argument = read_frame(pipe)
    assert command == "step" and argument["until"] == 10
    assert np.frombuffer(argument["rx"], RX_DTYPE)["msg_id"].tolist() == [4, 5, 6]
    assert read_frame(pipe) == ("exit", None)


def test_a_pipe_closed_mid_frame_is_an_end_of_file():
    pipe = io.BytesIO()
    write_frame(pipe, ("ping", None))
    cut = io.BytesIO(pipe.getvalue()[:-3])
    with pytest.raises(EOFError):
        read_frame(cut)
    with pytest.raises(EOFError):
        read_frame(io.BytesIO())


def test_the_record_layouts_are_those_of_the_cpp_structs():
    # radio.cpp static_asserts sizeof(RxRecord) == 40 and sizeof(DropRecord) == 32
    assert RX_DTYPE.itemsize == 40 and DROP_DTYPE.itemsize == 32

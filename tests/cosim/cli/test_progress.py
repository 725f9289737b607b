"""The one-line progress display of long runs: on a terminal only, one line rewritten."""

from __future__ import annotations

import io

from cosim.cli.progress import ProgressLine


class Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def test_nothing_is_written_unless_the_stream_is_a_terminal():
    pipe = io.StringIO()
    line = ProgressLine(pipe, label="run: ")
    line(1.0, 10.0, 0.5)
    line.close()
    assert not line.enabled
    assert pipe.getvalue() == ""


def test_the_line_shows_sim_time_of_the_total_percentage_real_time_factor_and_wall_time():
    terminal = Terminal()
    line = ProgressLine(terminal, label="warehouse: ")
    line(2.5, 10.0, 0.5)
    assert terminal.getvalue() == (
        "\rwarehouse: t =     2.50 / 10 s   25.0 %       5.0x real time     0.5 s wall"
    )


def test_each_update_rewrites_the_line_and_pads_over_a_longer_previous_one():
    terminal = Terminal()
    line = ProgressLine(terminal)
    line(1.0, 10.0, 0.001)  # 1000x real time: a longer text than the next
    first = terminal.getvalue()
    line(2.0, 10.0, 1.0)
    second = terminal.getvalue()[len(first) :]
    assert second.startswith("\r") and "\n" not in second
    assert len(second) == len(first)  # padded with spaces to hide the longer line's end
    assert second.rstrip(" ").endswith("1.0 s wall")


def test_no_wall_time_yet_and_a_zero_duration_give_finite_figures():
    terminal = Terminal()
    line = ProgressLine(terminal)
    line(0.0, 0.0, 0.0)
    text = terminal.getvalue()
    assert "100.0 %" in text and "0.0x real time" in text


def test_closing_ends_the_line_once_and_only_if_something_was_shown():
    terminal = Terminal()
    line = ProgressLine(terminal)
    line.close()
    assert terminal.getvalue() == ""
    line(1.0, 2.0, 1.0)
    line.close()
    assert terminal.getvalue().endswith("s wall\n")
    assert terminal.getvalue().count("\n") == 1

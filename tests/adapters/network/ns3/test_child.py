"""The radio's process serves requests over its pipes, and ends when they close."""

from __future__ import annotations

import subprocess
import sys

import pytest

from adapters.network.ns3.wire import read_frame, write_frame

pytestmark = pytest.mark.slow


def test_it_answers_what_it_cannot_do_and_ends_when_the_run_closes_its_pipe():
    child = subprocess.Popen(
        [sys.executable, "-m", "adapters.network.ns3.child"],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        stderr=subprocess.DEVNULL,
    )
    assert child.stdin is not None and child.stdout is not None
    write_frame(child.stdin, ("fly", None))
    assert read_frame(child.stdout)[:2] == ("err", "ValueError")
    write_frame(child.stdin, ("reasons", None))
    status, reasons = read_frame(child.stdout)
    assert status == "ok" and reasons[9] == "preamble_detect_failure"
    child.stdin.close()  # the run went away
    assert child.wait(timeout=60) == 0

"""Two mixed-reality runs at once on one machine: each hears only its own robot."""

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from tests.conftest import REPO

DURATION_S = 3.0
"""Simulated (and wall-clock) length of each run (s)."""


def _start(out: Path) -> subprocess.Popen[str]:
    command = [
        sys.executable, "-m", "cosim", "run", "lab-real-in-virtual", "--standin",
        "--duration-s", str(DURATION_S), "--out", str(out),
    ]  # fmt: skip
    return subprocess.Popen(
        command,
        cwd=REPO,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        env={**os.environ, "PYTHONUNBUFFERED": "1"},
    )


@pytest.mark.slow
def test_two_mixed_reality_runs_at_once_each_hear_only_their_own_robot(tmp_path):
    runs = [tmp_path / "a", tmp_path / "b"]
    processes = [_start(out) for out in runs]
    outputs = []
    for process in processes:
        try:
            output, _ = process.communicate(timeout=120)
        finally:
            if process.poll() is None:
                process.kill()
                process.wait()
        outputs.append(output)
    for process, output in zip(processes, outputs, strict=True):
        assert process.returncode == 0, output
        assert "Traceback" not in output, output
    summaries = [json.loads((out / "summary.json").read_text()) for out in runs]
    domains = {summary["physical_dds_domain"] for summary in summaries}
    assert len(domains) == 2  # a domain each
    for summary, output in zip(summaries, outputs, strict=True):
        # the run says where its robot talks before it starts
        assert f"DDS domain {summary['physical_dds_domain']} on loopback" in output
        assert summary["mocap_rejected_jumps"] == 0  # never the other run's robot
        assert summary["mocap_rejected_out_of_order"] == 0
        assert summary["mocap_poses"] > 50 * DURATION_S  # its own robot, ~100 Hz
        assert summary["physical_commands_sent"] > 0

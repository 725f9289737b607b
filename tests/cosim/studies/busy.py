"""A study whose runs spend their time in FCL's callbacks, and a process running it again and again.

The runs of :func:`busy_study` hold many robots standing far apart among many small
obstacles: every physics step measures the smallest clearance with FCL's ``distance``,
whose Python callbacks are called from Cython code that drops any exception raised in
them (``Exception ignored in: 'fcl.fcl.DistanceCallBack'``). A signal whose handler raised
while such a callback ran used to be lost that way.

``python -m tests.cosim.studies.busy STUDY.toml FOLDER TRIALS`` runs ``cosim study STUDY
--workers 1`` in this one process ``TRIALS`` times (the process starts once: a trial costs
its runs only), each into ``FOLDER/trial_<k>``, and prints a line ``start <k> <out>``
before each trial and one JSON line (trial, exit status, stdout, stderr) after it; a test
sends it signals from outside at moments of its choosing.
"""

from __future__ import annotations

import contextlib
import io
import json
import sys
from pathlib import Path

SHORT_S, LONG_S = 0.05, 60.0
"""Simulated seconds of the study's two runs: one done at once, one long enough to stop."""
SHORT_RUN, LONG_RUN = "0000_s1", "0001_s1"
"""Their run ids."""


def busy_scenario(folder: Path, *, per_side: int = 10, cell_m: float = 3.0) -> Path:
    """A scenario of ``per_side**2`` robots standing still, each in a cell with an obstacle.

    Teleoperated robots with no operator keep where they start, more than twice the
    near-miss margin from anything, so every step asks FCL for the smallest clearance.
    """
    size = per_side * cell_m
    cells = [(i * cell_m, j * cell_m) for i in range(per_side) for j in range(per_side)]
    positions = [[x + cell_m / 2, y + cell_m / 2, 0.0] for x, y in cells]
    obstacles = [[x + 0.1, y + 0.1, x + 0.4, y + 0.4] for x, y in cells]
    text = f"""\
extends = "warehouse-random"

[scenario]
name = "busy"

[world]
size_m = [{size}, {size}]
shelf_count = 0
obstacles = {json.dumps(obstacles)}

[robots]
count = {len(positions)}
placement = "explicit"
positions = {json.dumps(positions)}
driver = "teleop"

[lidar]
beams = 0

[record]
bag = "none"
messages = false
"""
    path = folder / "busy.toml"
    path.write_text(text, encoding="utf-8")
    return path


def busy_study(folder: Path) -> Path:
    """A study of :func:`busy_scenario`: a run of :data:`SHORT_S`, then one of :data:`LONG_S`."""
    busy_scenario(folder)
    path = folder / "study.toml"
    path.write_text(
        f"""\
[study]
name = "busy"
scenario = "busy.toml"
seeds = [1]

[grid]
"scenario.duration_s" = [{SHORT_S}, {LONG_S}]
""",
        encoding="utf-8",
    )
    return path


def trials(study: Path, folder: Path, count: int) -> None:
    """Run ``cosim study`` ``count`` times in this process; say when each starts and ends."""
    from cosim.cli.main import main

    for k in range(count):
        out = folder / f"trial_{k}"
        print(f"start {k} {out}", flush=True)
        said, errors = io.StringIO(), io.StringIO()
        with contextlib.redirect_stdout(said), contextlib.redirect_stderr(errors):
            status = main(["study", str(study), "--out", str(out), "--workers", "1", "--quiet"])
        line = {"trial": k, "status": status, "stdout": said.getvalue()}
        print(json.dumps({**line, "stderr": errors.getvalue()}), flush=True)


if __name__ == "__main__":
    trials(Path(sys.argv[1]), Path(sys.argv[2]), int(sys.argv[3]))

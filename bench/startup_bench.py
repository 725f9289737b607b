"""How long the command line takes to answer: ``cosim --help`` in a fresh process."""

from __future__ import annotations

import json
import statistics
import subprocess
import sys
from pathlib import Path
from typing import Any

COSIM = Path(sys.executable).with_name("cosim")

LAUNCHER = """
import json, os, resource, sys, time
start = time.perf_counter()
pid = os.fork()
if pid == 0:
    os.dup2(os.open(os.devnull, os.O_WRONLY), 1)
    os.execv(sys.argv[1], sys.argv[1:])
os.waitpid(pid, 0)
wall = time.perf_counter() - start
print(json.dumps([wall, resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss]))
"""
"""Times one command from a small process of its own: a child's peak memory counts the
memory of the process that forked it, so the benchmark's own (hundreds of MB) must not."""


def _once(command: list[str]) -> tuple[float, float]:
    out = subprocess.run(
        [sys.executable, "-c", LAUNCHER, *command], check=True, capture_output=True, text=True
    )
    wall, peak_kib = json.loads(out.stdout)
    return float(wall), peak_kib / 1024


def cli_startup(repeat: int) -> dict[str, Any]:
    """Wall time and peak memory of ``cosim --help`` (the parser alone), fresh processes.

    One warm-up (the file cache), then ``max(repeat, 7)`` timed runs.
    """
    command = [str(COSIM), "--help"]
    _once(command)
    runs = [_once(command) for _ in range(max(repeat, 7))]
    walls = [wall for wall, _ in runs]
    return {
        "command": "cosim --help",
        "wall_s_median": round(statistics.median(walls), 3),
        "wall_s_all": [round(w, 3) for w in walls],
        "peak_rss_mb_median": round(statistics.median(p for _, p in runs), 1),
    }

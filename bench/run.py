"""cosim benchmarks -> bench/results.json.

Each benchmark reports medians over several repetitions. Performance targets live here,
never in timed tests. Run ``make bench`` (all) or ``python bench/run.py --only NAME``.
Results of benchmarks not run this time are kept from the previous file.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent))

from suites import ON_REQUEST, SUITES

Result = dict[str, Any]


def machine() -> dict[str, Any]:
    return {
        "python": platform.python_version(),
        "machine": platform.machine(),
        "processor": platform.processor() or "unknown",
        "cpus": os.cpu_count(),
    }


def commit() -> str:
    """The measured code's commit (``+changes`` when the work tree differs from it)."""
    try:
        head = subprocess.run(
            ["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True, check=True
        ).stdout.strip()
        dirty = subprocess.run(
            ["git", "status", "--porcelain", "--untracked-files=no"],
            capture_output=True,
            text=True,
            check=True,
        ).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown"
    return head + ("+changes" if dirty else "")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("bench/results.json"))
    parser.add_argument("--only", action="append", choices=sorted(SUITES), help="run only these")
    parser.add_argument("--repeat", type=int, default=3, help="repetitions per measurement")
    args = parser.parse_args(argv)
    previous: dict[str, Any] = {}
    if args.out.exists():
        previous = json.loads(args.out.read_text()).get("benchmarks", {})
    results = dict(previous)
    code = commit()
    for name in args.only or sorted(set(SUITES) - ON_REQUEST):
        suite: Callable[[int], Result] = SUITES[name]
        print(f"bench {name} ...", flush=True)
        start = time.perf_counter()
        result = suite(args.repeat)
        result["bench_wall_s"] = round(time.perf_counter() - start, 2)
        result["measured"] = time.strftime("%Y-%m-%d %H:%M:%S")
        result["commit"] = code
        results[name] = result
        print(json.dumps(result, indent=2), flush=True)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps({"machine": machine(), "benchmarks": results}, indent=2) + "\n")
    print(f"wrote {args.out}")
    return 0


def median(values: list[float]) -> float:
    return statistics.median(values)


if __name__ == "__main__":
    raise SystemExit(main())

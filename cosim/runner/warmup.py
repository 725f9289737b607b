"""Compile and cache the models' numba kernels ahead, so that a first run shows its real speed.

``make setup`` runs ``python -m cosim.runner.warmup`` once after installing: a short run of
each of a few presets without an output folder calls every kernel those runs call, and numba
writes each compiled kernel to its on-disk cache (``cache=True``: ``__pycache__`` next to the
kernel's module, found again by every later run of the same install). Later runs load the
kernels in milliseconds instead of compiling them for about 13 s.
"""

from __future__ import annotations

import argparse
import sys
import time
from collections.abc import Sequence

WARMUPS: tuple[tuple[str, float, dict[str, object]], ...] = (
    ("warehouse-random", 20.0, {}),
    ("warehouse-rows", 10.0, {}),
    ("fleet50", 5.0, {}),
    ("warehouse-mapping", 5.0, {}),
)
"""Preset, simulated seconds and overrides of each warm-up run: the kernels ``make demo``
and the other presets call (navigation, costmaps, DWA, the fleet manager's traffic,
task assignment, scan matching)."""


def warm_up(presets: Sequence[str] | None = None) -> float:
    """Run each warm-up preset briefly, without output, and return the compile time (s).

    Args:
        presets: the presets of :data:`WARMUPS` to run (default: all).

    Returns:
        Wall-clock seconds numba spent compiling (0 when every kernel was cached already).
    """
    from cosim.runner.execute import run
    from cosim.scenario import load_scenario

    compiled_s = 0.0
    for name, duration_s, overrides in WARMUPS:
        if presets is not None and name not in presets:
            continue
        scenario = load_scenario(name, overrides=overrides)
        scenario = scenario.with_duration(duration_s)
        compiled_s += run(scenario).compile_time_s
    return compiled_s


def main(argv: Sequence[str] | None = None) -> int:
    """``python -m cosim.runner.warmup [PRESET ...]``: compile and cache the kernels."""
    parser = argparse.ArgumentParser(
        prog="python -m cosim.runner.warmup",
        description="compile and cache cosim's numba kernels (make setup runs this once)",
    )
    parser.add_argument("presets", nargs="*", help="presets to run (default: all warm-ups)")
    args = parser.parse_args(argv)
    start = time.perf_counter()
    compiled_s = warm_up(args.presets or None)
    wall_s = time.perf_counter() - start
    said = f"compiled and cached in {compiled_s:.1f} s" if compiled_s > 0 else "already cached"
    print(f"numba kernels {said} (warm-up {wall_s:.1f} s): runs load them from the cache")
    return 0


if __name__ == "__main__":
    sys.exit(main())

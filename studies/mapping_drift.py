"""Mapping real buildings on drift realizations: does the result depend on the one recorded?

Each shared building recording (``../shared/data``) carries one drifting odometry. This
study draws other realizations of the same drift model
(:func:`models.mapping.drift.drifting_odometry`, seeds 1..N), maps every one with
scan-to-map matching alone and with loop closure (``cosim map``'s defaults), and compares
the trajectory errors (ATE: RMS after rigid SE(2) alignment against ``/ground_truth``).
The shared realizations themselves come first. Drift seed 0 is no drift at all (odometry
equal to the reference): how far the mapper itself moves a trajectory that needed no
correction, its own error, reported apart.

    .venv/bin/python studies/mapping_drift.py --seeds 10 --workers 2

Writes studies/results/mapping_drift/{results.csv, report.md, ate_by_seed.png}.
Every building is mapped as recorded and cut short (:data:`SHORT_RANGE_M`, half the beams:
a small robot's lidar). Acceptance (issue 45): loop closure never more than 1 cm worse than
scan-to-map alone; within 5 % of the odometry's error on every building, cut and
realization (3 % the moonshot); >= 100x the recording's real time.
"""

from __future__ import annotations

import argparse
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
from matplotlib.ticker import FormatStrFormatter

from adapters.mapping.bagmap import map_scans
from adapters.mapping.recording import Recording, read_recording
from models.mapping.drift import drifting_odometry
from models.mapping.quality import ate_rmse

SHARED = Path(__file__).resolve().parents[2] / "shared" / "data"
BUILDINGS = {
    "aces_lidar": "ACES (Austin)",
    "fr079_lidar": "Freiburg 079",
    "fhw_lidar": "FHW Museum",
    "acapulco_lidar": "Acapulco Convention Center",
}
SHARED_REALIZATIONS = {  # recording: (building, the drift seed it was made with)
    "aces_lidar": ("aces_lidar", 7),
    "aces_lidar_s12": ("aces_lidar", 12),
    "aces_lidar_s13": ("aces_lidar", 13),
    "fr079_lidar": ("fr079_lidar", 11),
    "fhw_lidar": ("fhw_lidar", 7),
    "acapulco_lidar": ("acapulco_lidar", 7),
}
SHORT_RANGE_M = 10.0
"""The short-range cut: returns beyond this are no return, and every other beam is dropped
(a 10 m lidar of half the beams, like the small robots' sensors)."""
CUTS = ("full", "short")
EXACT_SEED = 0
"""The realization without drift: odometry equal to the reference."""
_recordings: dict[str, Recording] = {}


def _recording(name: str) -> Recording:
    if name not in _recordings:
        _recordings[name] = read_recording(SHARED / name, reference_topic="/ground_truth")
    return _recordings[name]


def cut_scans(recording: Recording, cut: str) -> tuple[np.ndarray, np.ndarray, float]:
    """The recording's ranges, angles and maximum range as ``cut`` leaves them.

    ``full``: as recorded. ``short``: every other beam, and readings beyond
    :data:`SHORT_RANGE_M` turned into no return (``inf``, REP 117), its maximum range.
    """
    if cut == "full":
        return recording.ranges_m, recording.angles_rad, recording.range_max_m
    ranges = np.array(recording.ranges_m[:, ::2], dtype=np.float32)
    ranges[~(ranges <= SHORT_RANGE_M)] = np.inf
    return ranges, recording.angles_rad[::2], min(SHORT_RANGE_M, recording.range_max_m)


def one(job: tuple[str, str, int, bool, str]) -> dict[str, Any]:
    """One realization of one building, cut as asked, mapped both ways."""
    building, source, seed, shared, cut = job
    recording = _recording(source)
    reference = recording.reference
    assert reference is not None
    if shared:
        odometry = recording.odometry
    elif seed == EXACT_SEED:
        odometry = np.array(reference, dtype=np.float64)
    else:
        odometry = drifting_odometry(reference, seed)
    ranges, angles, range_max_m = cut_scans(recording, cut)
    row: dict[str, Any] = {
        "building": building,
        "cut": cut,
        "seed": seed,
        "shared": shared,
        "odometry_ate_m": ate_rmse(odometry[:, :2], reference[:, :2], align=True),
    }
    for loops, key in ((False, "scan_to_map"), (True, "loop_closure")):
        mapped = map_scans(
            recording.stamps_ns, ranges, odometry, angles,
            range_min_m=recording.range_min_m, range_max_m=range_max_m,
            loop_closure=loops,
        )  # fmt: skip
        row[f"{key}_ate_m"] = ate_rmse(mapped.estimate_xy_m(), reference[:, :2], align=True)
        row[f"{key}_rtf"] = mapped.span_s / mapped.wall_s
        if loops and mapped.mapper.loops is not None:
            row["closures"] = mapped.mapper.loops.closures
            row["closures_not_needed"] = mapped.mapper.loops.not_needed
    return row


def _figure(frame: pd.DataFrame, path: Path) -> None:
    frame = frame[frame.seed != EXACT_SEED]
    cuts = [c for c in CUTS if (frame.cut == c).any()]
    fig, grid = plt.subplots(
        len(cuts), len(BUILDINGS), figsize=(4 * len(BUILDINGS), 3.8 * len(cuts)), sharey=True,
        squeeze=False,
    )  # fmt: skip
    panels = [
        (ax, building, title, cut)
        for row, cut in zip(grid, cuts, strict=True)
        for ax, (building, title) in zip(row, BUILDINGS.items(), strict=True)
    ]
    for ax, building, title, cut in panels:
        rows = frame[(frame.building == building) & (frame.cut == cut)].reset_index(drop=True)
        x = np.arange(len(rows))
        for key, label, style in (
            ("loop_closure", "with loop closure (default)",
             {"marker": "s", "s": 16, "color": "tab:orange"}),
            ("scan_to_map", "scan-to-map only (hollow: shows where the two coincide)",
             {"marker": "o", "s": 46, "facecolors": "none", "edgecolors": "tab:blue"}),
        ):  # fmt: skip
            share = 100 * rows[f"{key}_ate_m"] / rows.odometry_ate_m
            ax.scatter(x, share, label=label, **style)
        ax.axhline(5.0, color="k", lw=0.8, ls="--", label="goal: 5 % of odometry")
        ax.set_yscale("log")
        ax.yaxis.set_major_formatter(FormatStrFormatter("%g"))
        ax.yaxis.set_minor_formatter(FormatStrFormatter("%g"))
        ax.tick_params(axis="y", which="both", labelsize=7)
        ax.set_xticks(
            x, [f"{s}{'*' if sh else ''}" for s, sh in zip(rows.seed, rows.shared, strict=True)]
        )
        ax.tick_params(axis="x", labelsize=6, rotation=90)
        what = "as recorded" if cut == "full" else f"cut to {SHORT_RANGE_M:g} m, half the beams"
        ax.set_title(f"{title}\n{what}: {len(rows)} realizations", fontsize=9)
        ax.set_xlabel("drift seed (* the shared recordings')")
    for row in grid:
        row[0].set_ylabel("trajectory error, % of odometry's")
    grid[0][0].legend(fontsize=7, loc="upper right")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def _report(frame: pd.DataFrame, seeds: int, wall_s: float, workers: int) -> str:
    exact = frame[frame.seed == EXACT_SEED][
        ["building", "cut", "scan_to_map_ate_m", "loop_closure_ate_m"]
    ]
    frame = frame[frame.seed != EXACT_SEED]
    frame = frame.assign(
        diff_cm=100 * (frame.loop_closure_ate_m - frame.scan_to_map_ate_m),
        loop_pct=100 * frame.loop_closure_ate_m / frame.odometry_ate_m,
        s2m_pct=100 * frame.scan_to_map_ate_m / frame.odometry_ate_m,
    )
    summary = frame.groupby(["building", "cut"], sort=False).agg(
        realizations=("seed", "count"),
        odometry_ate_m=("odometry_ate_m", lambda v: f"{v.min():.2f}-{v.max():.2f}"),
        scan_to_map_ate_m=("scan_to_map_ate_m", lambda v: f"{v.min():.3f}-{v.max():.3f}"),
        loop_closure_ate_m=("loop_closure_ate_m", lambda v: f"{v.min():.3f}-{v.max():.3f}"),
        loop_pct_median=("loop_pct", "median"),
        loop_pct_max=("loop_pct", "max"),
        over_5pct=("loop_pct", lambda v: int((v > 5).sum())),
        worse_by_over_1cm=("diff_cm", lambda v: int((v > 1).sum())),
        largest_diff_cm=("diff_cm", "max"),
        loop_rtf_min=("loop_closure_rtf", "min"),
    )
    shown = frame[
        ["building", "cut", "seed", "shared", "odometry_ate_m", "scan_to_map_ate_m",
         "loop_closure_ate_m", "loop_pct", "diff_cm", "closures", "closures_not_needed"]
    ]  # fmt: skip
    return (
        "# Mapping on drift realizations\n\n"
        f"Each building's recording with its shared drift realization(s) and {seeds} more "
        "(drift seeds 1..N of the shared data's model); scan-to-map matching alone and with "
        f"loop closure (`cosim map`'s defaults). {wall_s:.0f} s wall on {workers} workers.\n\n"
        "![trajectory error by drift seed](ate_by_seed.png)\n\n"
        "## Per building\n\n"
        + summary.round(2).to_markdown()
        + "\n\n## Per realization\n\n"
        + shown.round(4).to_markdown(index=False)
        + "\n\n## Without drift: the mapper's own error\n\n"
        "Odometry equal to the reference (drift seed 0): any error below is the mapper's "
        "own, moving poses that needed no correction.\n\n"
        + exact.round(4).to_markdown(index=False)
        + "\n"
    )


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=10, help="drift seeds 1..N per building")
    parser.add_argument("--workers", type=int, default=2, help="processes")
    parser.add_argument(
        "--building", choices=["all", *BUILDINGS], default="all", help="one building only"
    )
    parser.add_argument(
        "--cut", choices=["all", *CUTS], default="all", help="as recorded, short-range, or both"
    )
    parser.add_argument(
        "--out", type=Path, default=Path(__file__).parent / "results" / "mapping_drift"
    )
    args = parser.parse_args(argv)
    missing = [n for n in SHARED_REALIZATIONS if not (SHARED / n).is_dir()]
    if missing:
        print(f"mapping_drift: {SHARED}/{missing[0]} is not beside this clone", file=sys.stderr)
        return 2
    cuts = CUTS if args.cut == "all" else (args.cut,)
    jobs = [
        (b, name, seed, True, cut)
        for cut in cuts
        for name, (b, seed) in SHARED_REALIZATIONS.items()
        if args.building in ("all", b)
    ]
    jobs += [
        (b, b, s, False, cut)
        for cut in cuts
        for b in BUILDINGS
        if args.building in ("all", b)
        for s in range(EXACT_SEED, args.seeds + 1)
    ]
    start = time.perf_counter()
    rows = []
    with ProcessPoolExecutor(args.workers) as pool:
        for k, row in enumerate(pool.map(one, jobs), 1):
            rows.append(row)
            print(
                f"[{k}/{len(jobs)}] {row['building']} ({row['cut']}) seed {row['seed']}: odometry "
                f"{row['odometry_ate_m']:.2f} m, scan-to-map {row['scan_to_map_ate_m']:.3f} m, "
                f"loop closure {row['loop_closure_ate_m']:.3f} m",
                file=sys.stderr,
                flush=True,
            )
    frame = pd.DataFrame(rows)
    args.out.mkdir(parents=True, exist_ok=True)
    frame.to_csv(args.out / "results.csv", index=False)
    _figure(frame, args.out / "ate_by_seed.png")
    text = _report(frame, args.seeds, time.perf_counter() - start, args.workers)
    (args.out / "report.md").write_text(text)
    print(f"report: {args.out / 'report.md'}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

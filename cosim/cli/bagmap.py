"""``cosim map BAG --out DIR``: map a recording and write the results into a folder.

Writes ``map.pgm`` + ``map.yaml`` (map_server), ``map.png`` (the map with the
trajectories), ``trajectory.parquet`` and ``trajectory.csv`` (t_s, x_m, y_m, yaw_rad per
scan, stamps from the bag) and ``summary.json``. The mapping itself is
:func:`adapters.mapping.bagmap.map_recording`.

The folder is marked as cosim's (``.cosim-run``, :mod:`cosim.runner.runfolder`); ``--force``
replaces these files only in such a folder (or in one an earlier ``cosim map`` wrote before
folders were marked), never another's. The results are written whole inside the folder
first, then take their places (:mod:`cosim.runner.staging`).
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pandas as pd

from adapters.mapping.bagmap import Progress, RecordingMap, map_recording
from adapters.mapping.recording import check_topics
from adapters.world.files import write_map
from cosim.core.errors import ExportError
from cosim.runner.runfolder import MARKER, is_cosim_folder, mark
from cosim.runner.staging import discard, put_in_place, reason, stage_in
from models.mapping.matcher import MatcherParams
from models.mapping.slam import UpdateGate

OUTPUTS = ("map.pgm", "map.yaml", "map.png", "trajectory.parquet", "trajectory.csv", "summary.json")
"""What ``cosim map`` writes into its folder (``--force`` replaces exactly these)."""


@dataclass
class BagMapResult:
    """What ``cosim map`` produced.

    Attributes:
        out: the output folder.
        summary: counts, timings and trajectory errors (also in ``summary.json``).
        trajectory: t_s, x_m, y_m, yaw_rad per scan (the estimate, frame ``map``).
        files: the files written.
    """

    out: Path
    summary: dict[str, Any]
    trajectory: pd.DataFrame = field(repr=False)
    files: list[Path] = field(default_factory=list)


def map_bag(
    bag: Path,
    out: Path,
    *,
    scan_topic: str = "/scan",
    odom_topic: str = "/odom",
    reference_topic: str | None = None,
    resolution_m: float = 0.05,
    gate: UpdateGate | None = None,
    matcher: MatcherParams | None = None,
    scan_matching: bool = True,
    loop_closure: bool = True,
    clear_no_return_m: float = 3.0,
    force: bool = False,
    progress: Progress | None = None,
) -> BagMapResult:
    """Map a recorded bag and write the results into ``out``.

    Raises:
        BagError: one line naming the bag, topic, message and value, as
            :func:`~adapters.mapping.bagmap.map_recording`: not a bag, a topic missing or
            of the wrong type, unusable scans or poses, stamps not increasing, no scan that
            odometry covers, odometry spanning more than a map can hold.
        ExportError: ``out`` is not empty (without ``force``) or cannot be written.
        ValueError: ``resolution_m`` outside
            :data:`~adapters.mapping.bagmap.RESOLUTION_M` (the CLI refuses it as parsed).
    """
    bag, out = Path(bag), Path(out)
    check_topics(bag, scan_topic, odom_topic, reference_topic)
    _check_out(out, force)  # before the work; results replaced only once it succeeded
    mapped = map_recording(
        bag,
        scan_topic=scan_topic,
        odom_topic=odom_topic,
        reference_topic=reference_topic,
        resolution_m=resolution_m,
        gate=gate,
        matcher=matcher,
        scan_matching=scan_matching,
        loop_closure=loop_closure,
        clear_no_return_m=clear_no_return_m,
        progress=progress,
    )
    try:
        files = _write_outputs(out, mapped, bag.name)
    except OSError as error:
        raise ExportError(f"{out}: cannot write results ({reason(error)})") from None
    return BagMapResult(out, mapped.summary, mapped.trajectory, files)


def _write_outputs(out: Path, mapped: RecordingMap, bag_name: str) -> list[Path]:
    """Write the results whole into a staging folder in ``out``, then each in its place.

    Raises:
        OSError: the folder cannot take them (the staging folder is removed then).
        ExportError: some are written but cannot take their places: where they are.
    """
    from cosim.plotting.bagmap import bag_map_figure  # matplotlib only here

    out.mkdir(parents=True, exist_ok=True)
    stage = stage_in(out)
    try:
        mark(stage, "map")
        written = write_map(mapped.grid.occupancy_grid(), stage / "map.yaml")
        mapped.trajectory.to_parquet(stage / "trajectory.parquet", index=False)
        mapped.trajectory.to_csv(stage / "trajectory.csv", index=False)
        bag_map_figure(
            mapped.grid,
            mapped.estimate_xy_m,
            mapped.odometry_xy_m,
            mapped.reference_xy_m,
            stage / "map.png",
            bag_name,
        )
        (stage / "summary.json").write_text(
            json.dumps(mapped.summary, indent=2) + "\n", encoding="utf-8"
        )
    except BaseException:
        discard(stage)
        raise
    try:
        put_in_place(stage, out)
    except (OSError, ExportError) as error:
        why = reason(error) if isinstance(error, OSError) else str(error)
        raise ExportError(
            f"{out}: cannot put the results in place ({why}); those not in place are in {stage}/"
        ) from None
    discard(stage)
    names = [p.name for p in written] + [
        "trajectory.parquet",
        "trajectory.csv",
        "map.png",
        "summary.json",
    ]
    return [out / name for name in names]


def _check_out(out: Path, force: bool) -> None:
    if out.exists() and not out.is_dir():
        raise ExportError(f"{out}: exists and is not a folder")
    if not out.is_dir() or all(p.name == MARKER for p in out.iterdir()):
        return
    if not force:
        raise ExportError(f"{out}: folder is not empty; not overwriting (use --force)")
    if not is_cosim_folder(out, "map"):
        raise ExportError(
            f"{out}: not a folder of `cosim map` (no {MARKER}, nor its summary.json): --force "
            "replaces only an earlier map's files; choose another --out"
        )

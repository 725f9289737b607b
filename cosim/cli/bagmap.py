"""``cosim map BAG --out DIR``: map a recording and write the results into a folder.

Writes ``map.pgm`` + ``map.yaml`` (map_server), ``map.png`` (the map with the
trajectories), ``trajectory.parquet`` and ``trajectory.csv`` (t_s, x_m, y_m, yaw_rad per
scan, stamps from the bag) and ``summary.json``. The mapping itself is
:func:`adapters.mapping.bagmap.map_recording`.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pandas as pd

from adapters.mapping.bagmap import Progress, map_recording
from adapters.mapping.recording import check_topics
from adapters.world.files import write_map
from cosim.core.errors import ExportError
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
    _clear(out)
    out.mkdir(parents=True, exist_ok=True)
    try:
        files = write_map(mapped.grid.occupancy_grid(), out / "map.yaml")
        mapped.trajectory.to_parquet(out / "trajectory.parquet", index=False)
        mapped.trajectory.to_csv(out / "trajectory.csv", index=False)
        from cosim.plotting.bagmap import bag_map_figure  # matplotlib only here

        files += [out / "trajectory.parquet", out / "trajectory.csv"]
        files.append(
            bag_map_figure(
                mapped.grid,
                mapped.estimate_xy_m,
                mapped.odometry_xy_m,
                mapped.reference_xy_m,
                out / "map.png",
                bag.name,
            )
        )
        (out / "summary.json").write_text(
            json.dumps(mapped.summary, indent=2) + "\n", encoding="utf-8"
        )
    except OSError as error:
        raise ExportError(f"{out}: cannot write results ({error})") from None
    files.append(out / "summary.json")
    return BagMapResult(out, mapped.summary, mapped.trajectory, files)


def _check_out(out: Path, force: bool) -> None:
    if out.exists() and not out.is_dir():
        raise ExportError(f"{out}: exists and is not a folder")
    if out.is_dir() and any(out.iterdir()) and not force:
        raise ExportError(f"{out}: folder is not empty; not overwriting (use --force)")


def _clear(out: Path) -> None:
    try:
        for name in OUTPUTS:
            (out / name).unlink(missing_ok=True)
    except OSError as error:
        raise ExportError(f"{out}: cannot replace earlier results ({error})") from None

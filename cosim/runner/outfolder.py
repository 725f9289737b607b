"""A run's folder: what a run writes there, replacing an earlier run's, and writing it.

A run writes ``summary.json`` (beginning with ``"format"``, :mod:`cosim.runner.runfolder`,
and with ``"plugins"``: whose code it ran, by package version), ``scenario.toml`` (beginning
with ``[provenance]``: those packages and versions), ``tables/NAME.parquet`` (one per table),
``bag/`` (``metadata.yaml`` and ``bag.mcap`` or ``bag.db3``), ``maps/NAME.yaml`` + ``.pgm``
(``fleet`` and ``robot_N``), SUMO's files in ``sumo/``, ``failure.txt`` for a failed run and,
drawn afterwards with ``--figures``/``--gif``, ``figures/``. The folder is marked as cosim's
(``.cosim-run``) before the run starts, which also proves it can be written.

``--force`` works only in a folder cosim wrote (marked, or a run folder of format 0) and
removes exactly those of an earlier run's files that this run writes again (the figures only
when it draws them: figures made with ``cosim plot`` stay otherwise) and leaves every other
file where it is; a file in the way of the new results (a stranger in ``bag/``, which
rosbags must create afresh; a folder named ``summary.json``) is named in one line instead of
being deleted.

The results are written inside the folder first, then take their places
(:mod:`cosim.runner.staging`): nothing beside the folder is used, so a folder on another
disk, a mount point or a folder in a read-only one takes them as any other. A folder that
cannot take them leaves them in a new folder of the system's temporary folder, and the
error says so.

A run without ``--out`` writes to ``runs/NAME-seedN``, or, when that folder holds results
already, to the first free ``runs/NAME-seedN-2``, ``-3``, ... (:func:`default_out`).
"""

from __future__ import annotations

import json
import re
from collections.abc import Iterator
from pathlib import Path
from typing import TYPE_CHECKING

from adapters.world.files import write_map
from cosim.core.errors import CosimError, ExportError
from cosim.recording.bag import BAG_DIR
from cosim.runner.faults import FAILURE_FILE, failure_text
from cosim.runner.provenance import packages
from cosim.runner.runfolder import FORMAT_KEY, MARKER, RUN_FORMAT, is_cosim_folder, mark
from cosim.runner.staging import (
    discard,
    put_in_place,
    reason,
    spare_folder,
    stage_in,
    stale_stagings,
)
from cosim.scenario.loader import dump_scenario
from models.geometry.occupancy import OccupancyGrid

if TYPE_CHECKING:
    from cosim.runner.result import RunResult

TOP_FILES = ("summary.json", "scenario.toml")
"""The files a run writes at the top of its folder."""
BAG_FILE = re.compile(r"metadata\.yaml|bag\.(?:mcap|db3)(?:-wal|-shm|-journal)?")
"""A bag's files: rosbags names the storage after the folder (``bag/bag.mcap``), sqlite3
adds its journal files while open."""
MAP_FILE = re.compile(r"(?:fleet|robot_\d+)\.(?:yaml|pgm)")
"""The maps a run writes (the merged fleet map and each robot's)."""
FIGURE_FILES = frozenset(
    (
        "trajectories.png",
        "snapshots.png",
        "tasks.png",
        "network.png",
        "assignment.png",
        "maps.png",
        "map_quality.png",
        "run.gif",
    )
)
"""What ``cosim plot`` (``cosim run --figures``) draws (:func:`cosim.plotting.command.plot_run`)."""
SUMO_FILE = re.compile(r"[^/]+\.(?:xml|sumocfg|log)")
"""What the people's SUMO session leaves in ``sumo/``."""
FOLDERS = ("tables", BAG_DIR, "maps", "figures", "sumo")
"""The folders a run writes into."""


def table_names() -> set[str]:
    """Every table a run can write: the recorder's, the runner's and every adapter's."""
    from cosim.core.recorder import EVENTS, MESSAGES
    from cosim.core.registry import AdapterRegistry

    names = {MESSAGES.name, EVENTS.name, "realtime"}
    for adapter in AdapterRegistry.from_entry_points().load_all().values():
        names.update(spec.name for spec in getattr(adapter, "tables", ()))
    return names


LAST = 1000
"""One past the last number :func:`default_out` tries (``runs/NAME-seedN-999``)."""


def default_out(base: Path) -> Path:
    """The folder a run without ``--out`` writes to: ``base``, or the first free numbered one.

    ``base`` (``runs/NAME-seedN``) when it does not exist or is an empty folder, else the
    first of ``base-2``, ``base-3``, ... that does not exist (made here, so that two runs
    started together do not take the same one).

    Raises:
        ExportError: the file system refuses to make the folder.
    """
    candidates = (base if n == 1 else base.with_name(f"{base.name}-{n}") for n in range(1, LAST))
    try:
        for folder in candidates:
            if folder.is_dir() and holds_nothing(folder):
                return folder
            try:
                folder.mkdir(parents=True)
            except FileExistsError:
                continue
            return folder
    except OSError as error:
        raise ExportError(f"{base}: cannot make the results folder ({reason(error)})") from None
    raise ExportError(
        f"{base}: it and {base.name}-2 to {base.name}-{LAST - 1} all exist; "
        "choose a folder with --out"
    )


def holds_nothing(folder: Path) -> bool:
    """Whether ``folder`` is empty but for cosim's mark."""
    return all(entry.name == MARKER for entry in folder.iterdir())


def _earlier_results(out: Path, *, figures: bool = True) -> Iterator[Path]:
    """The files of an earlier run in ``out`` that this run writes again, nothing else.

    Args:
        out: the run folder.
        figures: the run draws its figures (``--figures``): the earlier ones go too.
    """
    for name in (*TOP_FILES, FAILURE_FILE):
        if (out / name).is_file():
            yield out / name
    tables = out / "tables"
    if tables.is_dir() and any(tables.glob("*.parquet")):
        known = table_names()
        yield from (p for p in tables.glob("*.parquet") if p.is_file() and p.stem in known)
    for folder, written in (
        (BAG_DIR, BAG_FILE.fullmatch),
        ("maps", MAP_FILE.fullmatch),
        ("figures", FIGURE_FILES.__contains__),
        ("sumo", SUMO_FILE.fullmatch),
    ):
        if folder == "figures" and not figures:
            continue
        if (out / folder).is_dir():
            yield from (p for p in (out / folder).iterdir() if p.is_file() and written(p.name))


def _in_the_way(out: Path, doomed: set[Path], *, bag: bool, figures: bool) -> str | None:
    """What in ``out`` would keep a run from writing its results, said in one line."""
    for name in TOP_FILES:
        if (out / name).exists() and not (out / name).is_file():
            return f"{out / name}: is a folder where a run writes its {name}"
    for name in FOLDERS:
        if name == "figures" and not figures:
            continue
        if (out / name).exists() and not (out / name).is_dir():
            return f"{out / name}: is a file where a run writes its {name}/ folder"
    if bag and (out / BAG_DIR).is_dir():
        strangers = sorted(p.name for p in (out / BAG_DIR).iterdir() if p not in doomed)
        if strangers:
            more = f" and {len(strangers) - 1} more" if len(strangers) > 1 else ""
            return (
                f"{out / BAG_DIR}: holds {strangers[0]!r}{more}, which no run writes, and a "
                "new bag needs the folder to itself"
            )
    return None


def prepare_out(out: Path, *, force: bool, bag: bool = True, figures: bool = False) -> None:
    """Make sure ``out`` can take a run's results (made if new), and mark it as a run folder.

    Args:
        out: the run folder.
        force: in a folder cosim wrote, remove the files an earlier run wrote there that
            this run writes again (nothing else), and what a run killed outright left of
            its results on their way (``.cosim-partial-*``).
        bag: the run writes a bag (``bag/`` must then hold nothing but an earlier bag).
        figures: the run's figures are drawn into ``out/figures`` after it (``--figures``):
            ``force`` then removes the earlier figures; without it ``figures/`` stays as is.

    Raises:
        ExportError: ``out`` is a file, or a non-empty folder and ``force`` is false, or not
            a folder cosim wrote, or a file there is in the way of the results (nothing is
            removed then), or the file system refuses to write there.
    """
    try:
        if out.exists() and not out.is_dir():
            raise ExportError(f"{out}: exists and is not a folder; expected a folder to write to")
        if not out.exists():  # made now, so that a folder that cannot be is refused early
            out.mkdir(parents=True)
        elif not holds_nothing(out):
            _clear_earlier_run(out, force=force, bag=bag, figures=figures)
        mark(out)  # before the bag: this also proves the folder takes files
    except OSError as error:
        raise ExportError(f"{out}: cannot prepare the results folder ({reason(error)})") from None


def _clear_earlier_run(out: Path, *, force: bool, bag: bool, figures: bool) -> None:
    if not force:
        raise ExportError(f"{out}: folder is not empty; not overwriting (use --force)")
    if not is_cosim_folder(out):
        raise ExportError(
            f"{out}: not a run folder (no {MARKER}, nor the summary.json and scenario.toml "
            "of a run): --force replaces only an earlier run's files; choose another --out"
        )
    doomed = set(_earlier_results(out, figures=figures))
    problem = _in_the_way(out, doomed, bag=bag, figures=figures)
    if problem is not None:
        raise ExportError(f"{problem}; move it away or choose another --out")
    for path in sorted(doomed):
        path.unlink()
    for stale in stale_stagings(out):
        if stale.is_dir():
            discard(stale)
        else:
            stale.unlink()
    for name in FOLDERS:
        folder = out / name
        if folder.is_dir() and not any(folder.iterdir()):
            folder.rmdir()


def write_run(result: RunResult, out: Path, *, tables: bool = True) -> None:
    """Write a run's folder: whole inside ``out`` first, then each file in its place.

    Files of ``out`` that the run does not write stay (``--force`` removed an earlier
    run's). ``summary.json`` comes last: a folder with it holds the whole run. Where ``out``
    cannot take the results (full, read-only), they are written to a new folder of the
    system's temporary folder instead; nothing half-written is left in ``out``.

    Raises:
        ExportError: naming the folder, the reason, and where the results are then (the
            temporary folder, or the staging folder in ``out`` holding those not moved into
            place), or that none could be kept; its ``kept`` is ``result``.
    """
    out = Path(out)
    stage, refusal = _staged(result, out, tables=tables)
    if stage is None:
        kept = _spare_copy(result, out, tables=tables)
        where = f"they are kept in {kept}/ instead" if kept else "no copy could be kept"
        raise _unwritten(f"{out}: cannot write results ({refusal}); {where}", result, kept)
    try:
        put_in_place(stage, out)
    except (OSError, ExportError) as error:
        why = reason(error) if isinstance(error, OSError) else str(error)
        raise _unwritten(
            f"{out}: cannot put the results in place ({why}); those not in place are in {stage}/",
            result,
            stage,
        ) from None
    discard(stage)  # empty folders only, now
    result.out = out


def write_kept(error: CosimError, folder: Path, *, tables: bool) -> None:
    """Write what a run kept before ``error`` ended it (``error.kept``); say where in its message.

    A failed run's traceback goes with the results (``failure.txt``). When ``folder``
    cannot take them, the message says where they are instead (:func:`write_run`).
    """
    kept: RunResult = error.kept
    failure = kept.summary.get("failure")
    details = getattr(error, "details", "") and (
        isinstance(failure, dict) and failure.get("kind") in ("plugin", "cosim")
    )  # a traceback tells only of code that failed, not of a full disk or a silent robot
    if details:
        kept.files[FAILURE_FILE] = failure_text(error).encode()
    reached = kept.summary["sim_time_s"]
    says = ' (summary.json says "failed")' if "failed" in kept.summary else ""
    try:
        write_run(kept, folder, tables=tables)
    except ExportError as unwritten:  # said after the error that ended the run
        error.say_kept(f"the results of the {reached:g} s simulated: {unwritten}")
        return
    if details:
        error.say_kept(f"the traceback is in {folder / FAILURE_FILE}")
    error.say_kept(f"the results of the {reached:g} s simulated are in {folder}/{says}")


def _unwritten(message: str, result: RunResult, kept: Path | None) -> ExportError:
    error = ExportError(message)
    error.kept = result
    result.out = kept
    return error


def _staged(result: RunResult, out: Path, *, tables: bool) -> tuple[Path | None, str]:
    """The results written whole into a staging folder in ``out``, or None and why not."""
    stage = None
    try:
        out.mkdir(parents=True, exist_ok=True)
        stage = stage_in(out)
        _write_files(result, stage, tables=tables)
    except OSError as error:
        discard(stage)  # a half-written copy helps nobody and takes the space
        return None, reason(error)
    except BaseException:
        discard(stage)
        raise
    return stage, ""


def _spare_copy(result: RunResult, out: Path, *, tables: bool) -> Path | None:
    """The results written whole into a new temporary folder, or None if that fails too."""
    spare = None
    try:
        spare = spare_folder(out.name or "run")
        _write_files(result, spare, tables=tables)
    except BaseException as error:
        discard(spare)
        if isinstance(error, OSError):
            return None
        raise
    return spare


def _write_files(result: RunResult, folder: Path, *, tables: bool) -> None:
    """Write the run's files (and its mark) into ``folder``, ``summary.json`` last."""
    mark(folder)
    used = packages(result.summary.get("plugins", ()))
    (folder / "scenario.toml").write_text(
        dump_scenario(result.scenario, provenance=used), encoding="utf-8"
    )
    if tables:
        (folder / "tables").mkdir()
        for name, frame in result.tables.items():
            frame.to_parquet(folder / "tables" / f"{name}.parquet", index=False)
    for name, grid in result.maps.items():
        write_map(
            OccupancyGrid(grid.resolution_m, grid.origin_xy_m, grid.data),
            folder / "maps" / f"{name}.yaml",
        )
    for relative, data in result.files.items():
        target = folder / relative
        target.parent.mkdir(parents=True, exist_ok=True)
        target.write_bytes(data)
    summary = {FORMAT_KEY: RUN_FORMAT, **result.summary}
    (folder / "summary.json").write_text(
        json.dumps(summary, indent=2, allow_nan=False) + "\n", encoding="utf-8"
    )

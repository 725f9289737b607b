"""A run's folder: what a run writes there, replacing an earlier run's, and writing it.

A run writes ``summary.json`` (with ``"plugins"``: whose code it ran, by package version),
``scenario.toml`` (beginning with ``[provenance]``: those packages and versions),
``tables/NAME.parquet`` (one per table), ``bag/`` (``metadata.yaml`` and ``bag.mcap`` or
``bag.db3``), ``maps/NAME.yaml`` + ``.pgm`` (``fleet`` and ``robot_N``), SUMO's files in
``sumo/`` and, drawn afterwards with ``--figures``/``--gif``, ``figures/``. ``--force``
removes exactly those of an earlier run that this run writes again (the figures only when it
draws them: figures made with ``cosim plot`` stay otherwise) and leaves every other file
where it is; a file in the way of the new results (a stranger in ``bag/``, which rosbags
must create afresh; a folder named ``summary.json``) is named in one line instead of being
deleted.

A run without ``--out`` writes to ``runs/NAME-seedN``, or, when that folder holds results
already, to the first free ``runs/NAME-seedN-2``, ``-3``, ... (:func:`default_out`).
"""

from __future__ import annotations

import json
import os
import re
import shutil
from collections.abc import Iterator
from pathlib import Path
from typing import TYPE_CHECKING

from adapters.world.files import write_map
from cosim.core.errors import ExportError
from cosim.recording.bag import BAG_DIR
from cosim.runner.provenance import packages
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
            if folder.is_dir() and not any(folder.iterdir()):
                return folder
            try:
                folder.mkdir(parents=True)
            except FileExistsError:
                continue
            return folder
    except OSError as error:
        raise ExportError(f"{base}: cannot make the results folder ({_reason(error)})") from None
    raise ExportError(
        f"{base}: it and {base.name}-2 to {base.name}-{LAST - 1} all exist; "
        "choose a folder with --out"
    )


def _earlier_results(out: Path, *, figures: bool = True) -> Iterator[Path]:
    """The files of an earlier run in ``out`` that this run writes again, nothing else.

    Args:
        out: the run folder.
        figures: the run draws its figures (``--figures``): the earlier ones go too.
    """
    for name in TOP_FILES:
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
    """Make sure ``out`` can take a run's results (made if new); ``force`` clears an earlier run.

    Args:
        out: the run folder.
        force: remove the files an earlier run wrote there that this run writes again
            (nothing else).
        bag: the run writes a bag (``bag/`` must then hold nothing but an earlier bag).
        figures: the run's figures are drawn into ``out/figures`` after it (``--figures``):
            ``force`` then removes the earlier figures; without it ``figures/`` stays as is.

    Raises:
        ExportError: ``out`` is a file, or a non-empty folder and ``force`` is false, or a
            file there is in the way of the results (nothing is removed then), or the file
            system refuses.
    """
    try:
        if out.exists() and not out.is_dir():
            raise ExportError(f"{out}: exists and is not a folder; expected a folder to write to")
        if not out.exists():  # made now, so that a folder that cannot be is refused early
            out.mkdir(parents=True)
            return
        if not any(out.iterdir()):
            return
        if not force:
            raise ExportError(f"{out}: folder is not empty; not overwriting (use --force)")
        doomed = set(_earlier_results(out, figures=figures))
        problem = _in_the_way(out, doomed, bag=bag, figures=figures)
        if problem is not None:
            raise ExportError(f"{problem}; move it away or choose another --out")
        for path in sorted(doomed):
            path.unlink()
        for name in FOLDERS:
            folder = out / name
            if folder.is_dir() and not any(folder.iterdir()):
                folder.rmdir()
    except OSError as error:
        raise ExportError(f"{out}: cannot prepare the results folder ({_reason(error)})") from None


def _reason(error: OSError) -> str:
    return error.strerror or str(error)


def write_run(result: RunResult, out: Path, *, tables: bool = True) -> None:
    """Write a run's folder: into ``out.partial`` first, then moved into ``out`` file by file.

    Files of ``out`` that the run does not write stay (``--force`` removed an earlier run's).
    ``summary.json`` comes last: a folder with it holds the whole run. What cannot be
    written is not left half-written in ``out.partial`` (a full disk stays usable).

    Raises:
        ExportError: naming the folder when the file system refuses (full, read-only).
    """
    out = Path(out)
    partial = out.with_name(out.name + ".partial")
    try:
        if partial.exists():
            shutil.rmtree(partial)
        partial.mkdir(parents=True)
        used = packages(result.summary.get("plugins", ()))
        (partial / "scenario.toml").write_text(
            dump_scenario(result.scenario, provenance=used), encoding="utf-8"
        )
        if tables:
            (partial / "tables").mkdir()
            for name, frame in result.tables.items():
                frame.to_parquet(partial / "tables" / f"{name}.parquet", index=False)
        for name, grid in result.maps.items():
            write_map(
                OccupancyGrid(grid.resolution_m, grid.origin_xy_m, grid.data),
                partial / "maps" / f"{name}.yaml",
            )
        for relative, data in result.files.items():
            target = partial / relative
            target.parent.mkdir(parents=True, exist_ok=True)
            target.write_bytes(data)
        (partial / "summary.json").write_text(
            json.dumps(result.summary, indent=2, allow_nan=False) + "\n", encoding="utf-8"
        )
        out.mkdir(parents=True, exist_ok=True)
        _move_into(partial, out)
        shutil.rmtree(partial)
    except OSError as error:
        shutil.rmtree(partial, ignore_errors=True)
        raise ExportError(f"{out}: cannot write results ({_reason(error)})") from error
    except ExportError:
        shutil.rmtree(partial, ignore_errors=True)
        raise
    result.out = out


def _move_into(source: Path, target: Path) -> None:
    """Move every file of ``source`` to the same place in ``target``, replacing files there.

    Raises:
        ExportError: a folder stands where a file goes, or a file where a folder goes.
    """
    for entry in sorted(source.iterdir(), key=lambda e: (e.name == "summary.json", e.name)):
        place = target / entry.name
        if entry.is_dir():
            if not place.exists():
                entry.rename(place)
            elif place.is_dir():
                _move_into(entry, place)
            else:
                raise ExportError(f"{place}: is a file where a run writes a folder")
        elif place.is_dir():
            raise ExportError(f"{place}: is a folder where a run writes a file")
        else:
            os.replace(entry, place)

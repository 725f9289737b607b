"""A run folder (written by ``cosim run --out``) loaded and checked for drawing.

Everything comes from the folder alone, so any old run can be drawn: ``scenario.toml``
(the fully resolved scenario, from which the world is rebuilt exactly: same spec, same
seed, same random stream as the run) and ``tables/*.parquet``. Only the poses are
required; tasks, messages and assignments are optional (older runs, other drivers or
``record.messages = false`` lack them) and only the columns drawn are required of them.
A folder of any format is read (:func:`cosim.runner.runfolder.read_run_scenario`): keys
renamed since are read under their new names, sections of plugins no longer installed are
carried, each said in :attr:`RunData.notes`.
"""

from __future__ import annotations

import re
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from adapters.world.warehouse import scenario_warehouse
from cosim.core.errors import ExportError
from cosim.plotting.ownership import task_holds
from cosim.runner.runfolder import read_run_scenario
from cosim.scenario import Scenario
from models.arrays import FloatArray
from models.world.warehouse import Warehouse

TABLES_DIR = "tables"
POSE_COLUMNS = ("t_s", "robot", "x_m", "y_m", "yaw_rad")
TASK_COLUMNS = (
    "task",
    "x_m",
    "y_m",
    "t_created_s",
    "t_assigned_s",
    "robot",
    "t_started_s",
    "t_completed_s",
)
MESSAGE_COLUMNS = ("t_sent_s", "t_recv_s", "src_host", "dst_host", "topic", "status")
ASSIGNMENT_COLUMNS = ("epoch", "t_s", "robot", "round", "converged", "messages")
NAVIGATION_COLUMNS = ("t_s", "robot", "event", "goal_x_m", "goal_y_m")
HUMAN_COLUMNS = ("t_s", "id", "kind", "x_m", "y_m", "yaw_rad")
EVENT_COLUMNS = ("t_s", "source", "kind", "detail")
_NAMES = (
    "robot",
    "src_host",
    "dst_host",
    "topic",
    "status",
    "event",
    "id",
    "kind",
    "source",
    "detail",
)
"""Columns of names (categorical in the tables), read as plain strings."""


def robot_order(names: Iterable[str]) -> list[str]:
    """Robot names in fleet order: ``robot_2`` before ``robot_10`` (numbers compared as such)."""

    def key(name: str) -> tuple[str, int, str]:
        match = re.fullmatch(r"(.*?)(\d+)", name)
        return (match.group(1), int(match.group(2)), "") if match else (name, -1, name)

    return sorted(set(names), key=key)


@dataclass(frozen=True)
class Track:
    """Ground-truth poses of the fleet on a common time base (frame ``map``).

    Attributes:
        robots: robot names in fleet order (``robot_1``, ``robot_2``, ...).
        t_s: (T,) sample times (s), ascending.
        x_m: (T, R) positions along x (m); NaN where a robot has no sample.
        y_m: (T, R) positions along y (m).
        yaw_rad: (T, R) headings (rad, counter-clockwise from x).
    """

    robots: tuple[str, ...]
    t_s: FloatArray
    x_m: FloatArray
    y_m: FloatArray
    yaw_rad: FloatArray

    def index_at(self, t_s: float) -> int:
        """Index of the sample nearest to ``t_s`` (s)."""
        i = int(np.searchsorted(self.t_s, t_s))
        if i == len(self.t_s) or (i > 0 and t_s - self.t_s[i - 1] <= self.t_s[i] - t_s):
            i -= 1
        return i

    def since(self, i: int, trail_s: float) -> int:
        """Index of the first sample within ``trail_s`` (s) before sample ``i``."""
        return int(np.searchsorted(self.t_s, self.t_s[i] - trail_s - 1e-9))


@dataclass(frozen=True)
class RunData:
    """What the figures of a run are drawn from.

    Attributes:
        path: the run folder.
        scenario: the run's resolved scenario.
        warehouse: the run's world, rebuilt from the scenario (frame ``map``, m).
        track: the poses.
        tasks: ``tables/tasks`` (names as ``str``, ``""`` for no robot) plus ``holder``:
            the robot of its last holding (see ``holds``), ``""`` if none or if that robot
            released it; None when the run has no such table or it has no row.
        messages: ``tables/messages``, or None likewise.
        assignments: ``tables/assignments``, or None likewise.
        humans: ``tables/humans`` (people and forklifts moved by SUMO), or None likewise.
        holds: who held which task when (see :func:`cosim.plotting.ownership.task_holds`):
            a row per holding, ``task``, ``robot``, ``t_from_s``, ``t_to_s`` (NaN: still
            held at the end), ``end`` (``completed``, ``released`` or ``open``); None
            without tasks.
        navigation: ``tables/navigation`` (goals sent, arrivals), or None likewise.
        notes: one line each on how the folder was read (a key renamed since, a section of
            a plugin not installed), for the user.
    """

    path: Path
    scenario: Scenario
    warehouse: Warehouse
    track: Track
    tasks: pd.DataFrame | None
    messages: pd.DataFrame | None
    assignments: pd.DataFrame | None
    humans: pd.DataFrame | None = None
    holds: pd.DataFrame | None = None
    navigation: pd.DataFrame | None = None
    notes: tuple[str, ...] = ()

    @property
    def title(self) -> str:
        """Name and seed of the run, for figure titles."""
        return f"{self.scenario.name} (seed {self.scenario.seed})"


def load_run(run_dir: Path) -> RunData:
    """Load and check a run folder.

    Raises:
        ExportError: ``run_dir`` is not a folder, has no ``scenario.toml`` or no
            ``tables/poses.parquet``, is of a newer format than this cosim reads, a table
            cannot be read, lacks a column drawn, or has no pose; the message names the
            path and what was expected.
        ConfigError: ``scenario.toml`` is invalid (naming the file and key).
        ScenarioError: the world of the scenario cannot be rebuilt.
    """
    run_dir = Path(run_dir)
    if not run_dir.is_dir():
        raise ExportError(f"{run_dir}: no such folder; expected a run folder (cosim run --out)")
    scenario = read_run_scenario(run_dir)
    poses_path = run_dir / TABLES_DIR / "poses.parquet"
    poses = _read(poses_path, "poses", POSE_COLUMNS)
    if poses.empty:
        raise ExportError(f"{poses_path}: no pose; expected the poses of at least one robot")
    tasks = _optional(run_dir, "tasks", TASK_COLUMNS)
    navigation = _optional(run_dir, "navigation", NAVIGATION_COLUMNS)
    events = _optional(run_dir, "events", EVENT_COLUMNS)
    track = _track(poses, poses_path)
    holds = None if tasks is None else task_holds(tasks, navigation, events, robots=track.robots)
    return RunData(
        path=run_dir,
        scenario=scenario,
        warehouse=scenario_warehouse(scenario),
        track=track,
        tasks=_with_holder(tasks, holds),
        messages=_optional(run_dir, "messages", MESSAGE_COLUMNS),
        assignments=_optional(run_dir, "assignments", ASSIGNMENT_COLUMNS),
        humans=_optional(run_dir, "humans", HUMAN_COLUMNS),
        holds=holds,
        navigation=navigation,
        notes=scenario.notes,
    )


def _with_holder(tasks: pd.DataFrame | None, holds: pd.DataFrame | None) -> pd.DataFrame | None:
    """The tasks table plus ``holder``: its last holding's robot unless that one released it."""
    if tasks is None or holds is None:
        return tasks
    last = holds.groupby("task", sort=False).last()
    kept = last[last["end"] != "released"]["robot"]
    holder = dict(zip(kept.index.astype(float), kept.astype(str), strict=True))
    return tasks.assign(holder=[holder.get(float(k), "") for k in tasks["task"]])


def _optional(run_dir: Path, name: str, columns: tuple[str, ...]) -> pd.DataFrame | None:
    """The table ``name`` of the run, or None if it has no such table or no row."""
    path = run_dir / TABLES_DIR / f"{name}.parquet"
    if not path.is_file():
        return None
    frame = _read(path, name, columns)
    return None if frame.empty else frame


def _read(path: Path, name: str, columns: tuple[str, ...]) -> pd.DataFrame:
    """The drawn ``columns`` of a table: names as ``str``, flags as bool, the rest as float."""
    if not path.is_file():
        raise ExportError(f"{path}: no such file; expected the {name} table of a run")
    try:
        frame = pd.read_parquet(path)
    except (OSError, ValueError) as error:  # pyarrow's ArrowInvalid is a ValueError
        message = str(error).splitlines()[0] if str(error) else type(error).__name__
        raise ExportError(f"{path}: cannot read as a parquet table: {message}") from None
    if missing := [c for c in columns if c not in frame.columns]:
        raise ExportError(f"{path}: no column {', '.join(missing)}; expected {', '.join(columns)}")
    out = pd.DataFrame(index=pd.RangeIndex(len(frame)))
    for column in columns:
        values = frame[column].reset_index(drop=True)
        if column in _NAMES:
            out[column] = values.astype("string").fillna("").astype(str)
        elif pd.api.types.is_bool_dtype(values):
            out[column] = values.astype(bool)
        else:
            try:
                out[column] = pd.to_numeric(values, errors="raise").astype("float64")
            except (TypeError, ValueError):
                raise ExportError(
                    f"{path}: column {column} holds {values.dtype} values; expected numbers"
                ) from None
    return out


def _track(poses: pd.DataFrame, path: Path) -> Track:
    if poses.duplicated(["t_s", "robot"]).any():
        raise ExportError(f"{path}: more than one pose of a robot at one time; expected one")
    robots = robot_order(poses["robot"])
    wide = poses.pivot(index="t_s", columns="robot").sort_index()
    t_s = wide.index.to_numpy(dtype=np.float64)
    if not np.isfinite(t_s).all():
        raise ExportError(f"{path}: t_s holds non-finite times; expected seconds")

    def matrix(column: str) -> FloatArray:
        values: FloatArray = wide[column][robots].to_numpy(dtype=np.float64)
        return values

    return Track(tuple(robots), t_s, matrix("x_m"), matrix("y_m"), matrix("yaw_rad"))

"""The outcome of a run: its scenario, summary and tables, and what else it left."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pandas as pd

from cosim.core.errors import CosimError
from cosim.core.recorder import MapArtifact
from cosim.scenario.model import Scenario

RECORD_KEYS = ("failure", "plugins", "thread_busy")
"""Summary entries cosim itself writes that are records, not flat metrics: whose fault a
failed run was (``failure``), the plugins a run used (``plugins``) and how busy its
threads were (``thread_busy``)."""


@dataclass
class RunResult:
    """The outcome of a run.

    Attributes:
        scenario: the scenario that ran (with its seed and duration).
        summary: flat metrics and provenance.
        tables: DataFrames by table name (``poses``, ``messages``, ``events``, ...).
        out: the run folder, when written.
        bag: the bag directory, when one was written.
        recorded: messages recorded per topic (bag or live view).
        maps: final occupancy maps by name (written as ``maps/NAME.yaml`` + ``.pgm``).
        files: other files for the run folder by relative path (SUMO's ``sumo/...``).
        stopped: the signal that stopped the run before its duration, or None (the
            summary then says ``"stopped"`` and the simulated time reached).
        failure: the error of an external system that ended the run early (a robot or a
            motion-capture server gone silent), or None; the summary then says ``"failed"``.
        compile_time_s: wall-clock seconds numba spent compiling kernels for this run (s;
            about 13 s on a machine's first run, 0 once they are cached); the summary's
            ``wall_time_s`` and ``real_time_factor`` leave it out.
    """

    scenario: Scenario
    summary: dict[str, Any]
    tables: dict[str, pd.DataFrame] = field(repr=False)
    out: Path | None = None
    volatile: dict[str, tuple[str, ...]] = field(default_factory=dict, repr=False)
    bag: Path | None = None
    recorded: dict[str, int] = field(default_factory=dict, repr=False)
    maps: dict[str, MapArtifact] = field(default_factory=dict, repr=False)
    files: dict[str, bytes] = field(default_factory=dict, repr=False)
    stopped: int | None = None
    failure: CosimError | None = field(default=None, repr=False)
    compile_time_s: float = 0.0

    def deterministic_tables(self) -> dict[str, pd.DataFrame]:
        """The tables without their wall-clock columns: equal for equal scenario and seed."""
        return {
            name: frame.drop(columns=list(self.volatile.get(name, ())))
            for name, frame in self.tables.items()
        }

"""Run folders to draw, made once per session from small scenarios (well under a second each)."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

import cosim
from tests.conftest import SMALL

TASKS = {**SMALL, "robots.driver": "tasks", "scenario.duration_s": 20.0, "tasks.dwell_s": 0.5}
"""3 robots serving tasks by distributed simplex: every table a run can write."""
PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


def _run(folder: Path, overrides: dict[str, object]) -> Path:
    cosim.run(cosim.load_scenario("warehouse-random", overrides=overrides), out=folder)
    return folder


@pytest.fixture(scope="session")
def task_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A run folder with tasks, assignments, navigation and messages between hosts."""
    return _run(tmp_path_factory.mktemp("runs") / "tasks", TASKS)


@pytest.fixture(scope="session")
def waypoint_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A run folder without tasks or assignments whose messages never leave their host."""
    return _run(tmp_path_factory.mktemp("runs") / "waypoints", SMALL)


@pytest.fixture
def copy_of(tmp_path: Path):
    """Copy a session run folder into this test's own folder (to damage it safely)."""

    def copy(run_dir: Path) -> Path:
        return Path(shutil.copytree(run_dir, tmp_path / run_dir.name))

    return copy

"""Shared fixtures: small scenarios that run in well under a second, and one recorded run."""

from __future__ import annotations

import contextlib
import io
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import pytest

import cosim
from cosim.runner.result import RunResult
from cosim.scenario import Scenario

if TYPE_CHECKING:
    from tests.bags import DecodedBag

REPO = Path(__file__).resolve().parent.parent
SHARED_DATA = REPO.parent / "shared" / "data"

SMALL = {
    "scenario.duration_s": 3.0,
    "world.size_m": [12.0, 12.0],
    "world.shelf_count": 4,
    "robots.count": 3,
    "lidar.beams": 90,
    "robots.driver": "waypoints",
}


@dataclass
class Done:
    """What a command line said: its exit status and what it wrote."""

    returncode: int
    stdout: str
    stderr: str


def cosim_main(*args: str, cwd: Path | None = None) -> Done:
    """Run ``cosim ARGS`` in this process (as ``python -m cosim`` would, without the start-up).

    Output is captured; argparse's exits give their status. The tests that are about the
    process itself (signals, the interpreter's exit) start ``python -m cosim`` instead.
    """
    from cosim.cli.main import main

    out, err = io.StringIO(), io.StringIO()
    with (
        contextlib.chdir(cwd or Path.cwd()),
        contextlib.redirect_stdout(out),
        contextlib.redirect_stderr(err),
    ):
        try:
            code = main(list(args))
        except SystemExit as exit_:
            code = exit_.code if isinstance(exit_.code, int) else (0 if exit_.code is None else 1)
    return Done(code, out.getvalue(), err.getvalue())


@pytest.fixture
def small_scenario() -> Scenario:
    """A 12 m x 12 m hall, 4 shelves, 3 robots, 90-beam lidar, 3 s."""
    return cosim.load_scenario("warehouse-random", overrides=SMALL)


@pytest.fixture(scope="session")
def task_run(tmp_path_factory: pytest.TempPathFactory) -> RunResult:
    """A recorded 6 s run of 3 robots with tasks (MCAP bag, default topics)."""
    from tests.bags import TASKS

    scenario = cosim.load_scenario("warehouse-random", overrides=TASKS)
    return cosim.run(scenario, out=tmp_path_factory.mktemp("runs") / "tasks")


@pytest.fixture(scope="session")
def task_bag(task_run: RunResult) -> DecodedBag:
    """Every message of ``task_run``'s bag, decoded independently."""
    from tests.bags import mcap_file, read_mcap

    assert task_run.bag is not None
    return read_mcap(mcap_file(task_run.bag))


@pytest.fixture
def nav2_bag() -> Path:
    path = SHARED_DATA / "nav2_turtlebot.mcap"
    if not path.is_file():
        pytest.skip(f"{path} (the shared sample data) is not beside this clone")
    return path


LEFT_OUT = pytest.StashKey[int]()
"""How many tests the marker expression left out (``-m "not slow"``)."""


def pytest_deselected(items: list[pytest.Item]) -> None:
    """Count what ``-m`` leaves out, also on an xdist worker (which tells the controller)."""
    if not items:
        return
    config = items[0].config
    config.stash[LEFT_OUT] = config.stash.get(LEFT_OUT, 0) + len(items)
    workeroutput = getattr(config, "workeroutput", None)
    if workeroutput is not None:
        workeroutput["left_out"] = config.stash[LEFT_OUT]


@pytest.hookimpl(optionalhook=True)
def pytest_testnodedown(node: Any, error: Any) -> None:
    """Every xdist worker collects (and leaves out) the same tests: keep one count."""
    left_out = getattr(node, "workeroutput", {}).get("left_out", 0)
    node.config.stash[LEFT_OUT] = max(node.config.stash.get(LEFT_OUT, 0), left_out)


def pytest_terminal_summary(
    terminalreporter: pytest.TerminalReporter, config: pytest.Config
) -> None:
    """Say how many slow tests a fast run left out, and how to run them."""
    if "not slow" not in (config.option.markexpr or ""):
        return
    left_out = config.stash.get(LEFT_OUT, 0)
    terminalreporter.write_line(
        f"left out {left_out} slow tests (whole runs, SUMO, DDS, Dask, real time): "
        "`make test` runs every test"
    )

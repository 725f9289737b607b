"""Each kind of failure has its exit status and its line: input, a plugin, cosim, a study."""

from pathlib import Path

import pandas as pd
import pytest

from cosim.cli.exits import EXIT_STATUSES, failed_runs_line, say_error
from cosim.core.errors import BridgeError, ConfigError
from cosim.core.kernel import Stage
from cosim.core.plugins import PluginError, PluginInfo
from cosim.core.registry import registered
from cosim.runner.faults import InternalError
from tests.conftest import cosim_main

PLUGIN = PluginInfo("labkit", "0.1.0", "cosim.adapters", "prox", "labkit.prox:Prox")


@pytest.mark.parametrize(
    ("error", "status", "opening"),
    [
        (ConfigError("x.toml: robots.count = -1: expected >= 1"), 2, "cosim: error: x.toml"),
        (BridgeError("the vicon at 1.2.3.4 went silent"), 2, "cosim: error: the vicon"),
        (PluginError(PLUGIN, "raised KeyError: 'a'", t_ns=0), 3, "cosim: plugin error: adapter"),
    ],
)
def test_each_error_is_one_line_with_the_status_of_its_kind(capsys, error, status, opening):
    assert say_error(error) == status
    said = capsys.readouterr().err
    assert said.startswith(opening) and said.count("\n") == 1


def test_a_plugin_error_before_any_run_folder_prints_its_traceback(capsys):
    error = PluginError(PLUGIN, "raised KeyError: 'a'", details="Traceback (most recent...)\n")
    assert say_error(error) == 3
    assert capsys.readouterr().err.endswith("Traceback (most recent...)\n")


def test_cosims_own_failure_prints_the_traceback_and_says_it_is_a_bug(capsys):
    error = InternalError("raised KeyError: 'x'", details="Traceback (most recent call last)\n")
    assert say_error(error) == 1
    said = capsys.readouterr().err
    assert said.startswith("Traceback (most recent call last)\n")
    assert "cosim: internal error (a bug; please report it with the traceback above)" in said


def test_every_status_is_documented():
    assert set(EXIT_STATUSES) == {0, 1, 2, 3, 4, 130}


def test_a_studys_failed_runs_are_counted_by_whose_fault_and_named():
    results = pd.DataFrame(
        {
            "run_id": [f"r{i}" for i in range(8)],
            "status": ["ok", "error", "error", "ok", "error", "error", "error", "error"],
            "failure_kind": ["", "plugin", "plugin", "", "cosim", "plugin", "plugin", "plugin"],
        }
    )
    line = failed_runs_line(results, Path("runs/studies/s"))
    assert line.startswith("6 of 8 runs failed (5 in a plugin, 1 in cosim): r1, r2, r4, r5, r6,")
    assert "runs/studies/s/runs/RUN/failure.txt" in line


class Crashing:
    """An adapter whose callback fails after a second of simulated time."""

    name = "crashing"
    requires = ()

    def __init__(self, run):
        pass

    def start(self, run):
        run.kernel.every(500_000_000, self.tick, stage=Stage.CONTROL)

    def tick(self, now_ns):
        if now_ns >= 1_000_000_000:
            raise RuntimeError("lost the sensor")

    def finish(self, run):
        return {}


def test_cosim_run_exits_3_naming_the_plugin_and_keeps_the_run(tmp_path):
    with registered("cosim.adapters", "crashing", Crashing):
        done = cosim_main(
            "run", "warehouse-random", "--quiet", "--duration-s", "3", "--out", "run",
            "--set", 'scenario.adapters=["crashing"]', "--set", "robots.count=2",
            cwd=tmp_path,
        )  # fmt: skip
    assert done.returncode == 3
    assert done.stderr.count("\n") == 1 and "Traceback" not in done.stderr
    assert done.stderr.startswith(
        f"cosim: plugin error: adapter 'crashing' ({__name__}:Crashing, given in code) "
        "raised RuntimeError: lost the sensor in Crashing.tick (cli/test_exits.py:"
    )
    assert "at t = 1 s simulated; the traceback is in run/failure.txt" in done.stderr
    assert (tmp_path / "run" / "failure.txt").is_file()
    assert (tmp_path / "run" / "tables" / "poses.parquet").is_file()


SENSOR = '''"""A sensor adapter that loses its device after a second of simulated time."""

from cosim.core.kernel import Stage


class Sensor:
    name = "faulty_sensor"
    requires = ()

    def __init__(self, run):
        self.fails = run.scenario.seed % 2 == 1

    def start(self, run):
        run.kernel.every(500_000_000, self.read, stage=Stage.SENSING)

    def read(self, now_ns):
        if self.fails and now_ns >= 1_000_000_000:
            raise OSError("device gone")

    def finish(self, run):
        return {}
'''
STUDY = """
[study]
name = "faulty"
scenario = "warehouse-random"
seeds = 4
duration_s = 3.0

[overrides]
"robots.count" = 2
"scenario.adapters" = ["faulty_sensor"]
"""


@pytest.fixture(scope="module")
def faultykit(tmp_path_factory):
    """An environment where faultykit 0.3.1 is installed, with its failing sensor adapter."""
    from tests.packages import env_with, write_package

    site = tmp_path_factory.mktemp("site")
    write_package(
        site,
        "faultykit",
        "0.3.1",
        {"cosim.adapters": {"faulty_sensor": "faultykit.sensor:Sensor"}},
        {"faultykit/__init__.py": "", "faultykit/sensor.py": SENSOR},
    )
    return env_with(site)


def _cosim(env, *args, cwd):
    import subprocess
    import sys

    return subprocess.run(
        [sys.executable, "-m", "cosim", *args],
        capture_output=True, text=True, env=env, cwd=cwd, timeout=300,
    )  # fmt: skip


@pytest.mark.slow
def test_an_installed_plugins_fault_names_its_package_and_version(faultykit, tmp_path):
    done = _cosim(
        faultykit, "run", "warehouse-random", "--quiet", "--duration-s", "3", "--seed", "1",
        "--out", "run", "--set", 'scenario.adapters=["faulty_sensor"]', cwd=tmp_path,
    )  # fmt: skip
    assert done.returncode == 3, done.stderr
    assert done.stderr == (
        "cosim: plugin error: adapter 'faulty_sensor' (faultykit.sensor:Sensor, faultykit "
        "0.3.1) raised OSError: device gone in Sensor.read (faultykit/sensor.py:18) while "
        "running the simulation at t = 1 s simulated; the traceback is in run/failure.txt; "
        'the results of the 1 s simulated are in run/ (summary.json says "failed")\n'
    )


@pytest.mark.slow
def test_a_study_on_two_worker_processes_counts_its_failed_runs_and_exits_4(faultykit, tmp_path):
    (tmp_path / "study.toml").write_text(STUDY)
    done = _cosim(faultykit, "study", "study.toml", "--out", "out", "--workers", "2", cwd=tmp_path)
    assert done.returncode == 4, done.stderr
    assert "cosim: 2 of 4 runs failed (2 in a plugin): " in done.stderr
    failed = sorted((tmp_path / "out" / "runs").glob("*/failure.txt"))
    assert len(failed) == 2
    assert all("faultykit 0.3.1" in f.read_text() for f in failed)

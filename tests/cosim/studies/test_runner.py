"""The study runner: validation, executors (local and a real Dask cluster), resume."""

import signal
import subprocess
import sys
import time
from pathlib import Path

import pandas as pd
import psutil
import pytest

import cosim
from cosim.core.errors import ConfigError
from cosim.studies import load_study, run_study
from cosim.studies.worker import VOLATILE_METRICS, Outcome
from tests.conftest import REPO, cosim_main
from tests.cosim.studies.small import on_its_way
from tests.dask_cluster import dask_cluster as start_dask_cluster

TINY = """
[study]
name = "tiny"
scenario = "warehouse-random"
seeds = 2
duration_s = {duration}

[grid]
"network.latency_ms" = [0, 50]
"assignment.protocol" = ["distributed_simplex", "greedy"]

[overrides]
"world.size_m" = [16.0, 16.0]
"world.shelf_count" = 6
"robots.count" = 3
"record.messages" = false
"""


def _study(tmp_path: Path, text: str = TINY, duration: float = 10.0) -> Path:
    path = tmp_path / "study.toml"
    path.write_text(text.format(duration=duration) if "{duration}" in text else text)
    return path


def _comparable(frame: pd.DataFrame) -> pd.DataFrame:
    frame = frame.drop(columns=[c for c in VOLATILE_METRICS if c in frame.columns])
    return frame.sort_values("run_id").reset_index(drop=True)


cli = cosim_main


def test_a_study_expands_every_combination_for_every_seed(tmp_path):
    spec = load_study(_study(tmp_path))
    runs = spec.runs()
    assert len(runs) == 2 * 2 * 2
    assert len({r.run_id for r in runs}) == len(runs)
    assert runs[0].overrides["network.latency_ms"] == 0
    assert runs[0].overrides["world.shelf_count"] == 6


@pytest.mark.slow
def test_results_are_identical_in_process_and_on_two_local_workers(tmp_path):
    spec = load_study(_study(tmp_path))
    one = run_study(spec, tmp_path / "one", workers=1)
    two = run_study(spec, tmp_path / "two", workers=2)
    assert len(one) == 8 and set(one["status"]) == {"ok"}
    pd.testing.assert_frame_equal(_comparable(one), _comparable(two))
    assert (tmp_path / "two" / "runs" / "0003_s2" / "summary.json").exists()


@pytest.fixture
def dask_cluster(tmp_path):
    """A real Dask scheduler and two workers, separate processes on loopback."""
    with start_dask_cluster(tmp_path) as cluster:
        yield cluster


@pytest.mark.slow
def test_a_study_gives_the_same_rows_on_a_real_dask_cluster_as_locally(tmp_path, dask_cluster):
    spec = load_study(_study(tmp_path))
    local = run_study(spec, tmp_path / "local", workers=1)
    remote = run_study(spec, tmp_path / "dask", scheduler=dask_cluster.address)
    assert set(remote["status"]) == {"ok"}
    pd.testing.assert_frame_equal(_comparable(local), _comparable(remote))


class _KillAfterFirstRun:
    """A study progress that SIGKILLs some processes once the first run has finished."""

    def __init__(self, victims) -> None:
        self.victims = victims
        self.killed: list[int] = []

    def begin(self, total: int, already_done: int) -> None:
        pass

    def __call__(self, outcome: Outcome) -> None:
        if not self.killed:
            for process in self.victims():
                process.send_signal(signal.SIGKILL)
                self.killed.append(process.pid)


@pytest.mark.slow
def test_a_study_survives_a_dask_worker_killed_mid_way_with_the_same_rows(tmp_path, dask_cluster):
    spec = load_study(_study(tmp_path))

    # the worker process proper is the nanny's spawned child (not its resource tracker);
    # the nanny starts a new one
    def worker_process():
        nanny = psutil.Process(dask_cluster.workers[0].pid)
        return [p for p in nanny.children() if "spawn_main" in " ".join(p.cmdline())]

    killer = _KillAfterFirstRun(worker_process)
    remote = run_study(spec, tmp_path / "dask", scheduler=dask_cluster.address, progress=killer)
    assert killer.killed, "no dask worker process to kill"
    local = run_study(spec, tmp_path / "local", workers=1)
    assert set(remote["status"]) == {"ok"}
    pd.testing.assert_frame_equal(_comparable(local), _comparable(remote))


@pytest.mark.slow
def test_a_study_killed_mid_way_and_resumed_has_every_run_exactly_once(tmp_path):
    path = _study(tmp_path, duration=40.0)
    out = tmp_path / "out"
    proc = subprocess.Popen(
        [sys.executable, "-m", "cosim", "study", str(path), "--out", str(out), "--workers", "1"],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    deadline = time.monotonic() + 120
    runs = out / "runs"
    while time.monotonic() < deadline:
        finished = [p for p in runs.iterdir() if not on_its_way(p)] if runs.exists() else []
        if len(finished) >= 2:
            break
        time.sleep(0.05)
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    killed_with = len([p for p in runs.iterdir() if not on_its_way(p)])
    assert 2 <= killed_with < 8
    refused = cli("study", str(path), "--out", str(out))
    assert refused.returncode == 2 and "--resume" in refused.stderr
    resumed = cli("study", str(path), "--out", str(out), "--resume", "--workers", "2")
    assert resumed.returncode == 0, resumed.stderr
    assert f"resuming, {killed_with}/8 runs already done" in resumed.stderr
    assert "study: 8/8 runs, 0 failed" in resumed.stderr
    results = pd.read_parquet(out / "results.parquet")
    assert sorted(results["run_id"]) == sorted(r.run_id for r in load_study(path).runs())
    assert results["run_id"].is_unique
    assert not [p for p in runs.iterdir() if on_its_way(p)]
    assert len(list(runs.iterdir())) == 8


@pytest.mark.slow
def test_a_local_worker_process_killed_stops_the_study_cleanly_and_resume_finishes_it(tmp_path):
    path = _study(tmp_path, duration=40.0)
    out = tmp_path / "out"
    proc = subprocess.Popen(
        [sys.executable, "-m", "cosim", "study", str(path), "--out", str(out), "--workers", "2"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and not [
        p for p in (out / "runs").glob("*") if not on_its_way(p)
    ]:
        time.sleep(0.05)
    # the pool's workers are the fork server's children, the study's grandchildren
    study = psutil.Process(proc.pid)
    workers = [p for p in study.children(recursive=True) if p.ppid() != proc.pid]
    assert workers, "no worker process found"
    workers[0].send_signal(signal.SIGKILL)
    _, stderr = proc.communicate(timeout=120)
    assert proc.returncode == 2, stderr
    last = stderr.strip().splitlines()[-1]
    assert last.startswith("cosim: error: tiny: a worker process died"), stderr
    assert "continue with --resume" in last and "Traceback" not in stderr
    kept = pd.read_parquet(out / "results.parquet")
    assert 1 <= len(kept) < 8 and set(kept["status"]) == {"ok"}
    resumed = cli("study", str(path), "--out", str(out), "--resume", "--workers", "2")
    assert resumed.returncode == 0, resumed.stderr
    results = pd.read_parquet(out / "results.parquet")
    assert len(results) == 8 and results["run_id"].is_unique and set(results["status"]) == {"ok"}


def test_a_failing_run_is_recorded_and_the_others_go_on(tmp_path):
    text = TINY.replace('"world.shelf_count" = 6\n', "").replace(
        '"assignment.protocol" = ["distributed_simplex", "greedy"]',
        '"world.shelf_count" = [6, 400]',
    )
    results = run_study(load_study(_study(tmp_path, text)), tmp_path / "out", workers=1)
    failed = results[results["status"] == "error"]
    assert len(failed) == 4 and len(results) == 8
    assert failed["error"].str.contains("world.shelf_count = 400").all()
    assert set(results.loc[results["status"] == "ok", "world.shelf_count"]) == {6}


@pytest.mark.parametrize(
    ("edit", "fragment"),
    [
        (
            lambda t: t.replace('"network.latency_ms"', '"network.latency_mz"'),
            "unknown key 'latency_mz'; did you mean 'latency_ms'?",
        ),
        (lambda t: t.replace("[0, 50]", "[]"), "expected a non-empty list of values"),
        (lambda t: t.replace("[0, 50]", "[0, -50]"), "latency_ms = -50: expected a number >= 0"),
        (lambda t: t.replace("seeds = 2", "seeds = 0"), "seeds = 0"),
        (
            lambda t: t.replace('scenario = "warehouse-random"', 'scenario = "nowhere.toml"'),
            "scenario = 'nowhere.toml'",
        ),
        (lambda t: t + "\n[plots]\nx = 1\n", "unknown section [plots]"),
        (
            lambda t: t.replace("seeds = 2", 'seeds = 2\ntables = ["poses", "pose"]'),
            "tables = ['poses', 'pose']: no run of this study has 'pose' (expected some of",
        ),
        (
            lambda t: t + '\n[report]\nx = "network.latency_mz"\n',
            "[report] x = 'network.latency_mz': not a key this study sets",
        ),
        (
            lambda t: t + '\n[report]\nmetrics = "tasks_per_min"\n',
            "[report] metrics = 'tasks_per_min': expected a list of metric names",
        ),
        (
            lambda t: t + '\n[report]\nx = "network.latency_ms"\nheatmaps = ["conflicts"]\n',
            "heatmaps need x and facet",
        ),
    ],
)
def test_a_bad_study_file_exits_2_naming_the_key(tmp_path, edit, fragment):
    path = _study(tmp_path, edit(TINY.format(duration=5.0)))
    done = cli("study", str(path), "--out", str(tmp_path / "out"))
    assert done.returncode == 2, done.stdout
    assert fragment in done.stderr and str(path) in done.stderr
    assert done.stderr.count("\n") == 1, done.stderr
    assert not (tmp_path / "out").exists()
    with pytest.raises(ConfigError):
        load_study(path)


def test_the_python_api_returns_one_row_per_run(tmp_path):
    frame = cosim.study(_study(tmp_path, duration=5.0), tmp_path / "out", workers=1)
    assert len(frame) == 8
    assert {
        "run_id",
        "seed",
        "network.latency_ms",
        "assignment.protocol",
        "tasks_per_min",
        "wall_time_s",
        "status",
        "error",
    } <= set(frame.columns)


@pytest.mark.slow
def test_a_list_valued_override_becomes_a_text_column_the_report_can_group(tmp_path, monkeypatch):
    text = TINY.replace('"world.size_m" = [16.0, 16.0]\n', "") + (
        '\n[[cases]]\n"world.size_m" = [16.0, 16.0]\n'
        '\n[[cases]]\n"world.size_m" = [18.0, 18.0]\n'
        '\n[report]\nx = "network.latency_ms"\nhue = "world.size_m"\n'
        'metrics = ["tasks_per_min"]\n'
    )
    text = text.replace('"assignment.protocol" = ["distributed_simplex", "greedy"]\n', "")
    results = run_study(
        load_study(_study(tmp_path, text, duration=5.0)), tmp_path / "out", workers=1
    )
    assert set(results["world.size_m"]) == {"[16.0, 16.0]", "[18.0, 18.0]"}
    report = (tmp_path / "out" / "report.md").read_text()
    assert "[18.0, 18.0]" in report


def test_each_run_folder_keeps_its_scenario_summary_and_only_the_tables_asked_for(tmp_path):
    text = TINY.replace("seeds = 2", 'seeds = 1\ntables = ["poses", "tasks"]')
    out = tmp_path / "out"
    run_study(load_study(_study(tmp_path, text, duration=5.0)), out, workers=1)
    folders = sorted((out / "runs").iterdir())
    assert len(folders) == 4
    for folder in folders:
        assert {p.name for p in folder.iterdir()} == {
            "row.json",
            "summary.json",
            "scenario.toml",
            "tables",
        }
        assert {p.name for p in (folder / "tables").iterdir()} == {
            "poses.parquet",
            "tasks.parquet",
        }
        poses = pd.read_parquet(folder / "tables" / "poses.parquet")
        assert poses["t_s"].max() == pytest.approx(5.0, abs=0.2)


@pytest.mark.slow
def test_a_report_with_heatmaps_draws_one_per_metric_and_links_it(tmp_path):
    text = TINY + (
        '\n[report]\nx = "network.latency_ms"\nfacet = "assignment.protocol"\n'
        'metrics = ["tasks_per_min"]\nheatmaps = ["tasks_per_min"]\n'
    )
    run_study(load_study(_study(tmp_path, text, duration=5.0)), tmp_path / "out", workers=1)
    name = "tasks_per_min_over_network.latency_ms_and_assignment.protocol.png"
    assert (tmp_path / "out" / "figures" / name).stat().st_size > 10_000
    assert f"(figures/{name})" in (tmp_path / "out" / "report.md").read_text()


SHIPPED = sorted((REPO / "studies").glob("*.toml"))


@pytest.mark.parametrize("path", SHIPPED, ids=[p.stem for p in SHIPPED])
def test_every_shipped_study_file_loads_with_a_report_and_distinct_run_ids(path):
    spec = load_study(path)
    runs = spec.runs()
    assert runs and len({r.run_id for r in runs}) == len(runs)
    assert spec.report, f"{path.name} has no [report]"


class Flaky:
    """An adapter that fails in the runs with 50 ms of latency, after 2 simulated seconds."""

    name = "flaky"
    requires = ()

    def __init__(self, run):
        from adapters.network.settings import NetworkConfig

        self.fails = run.settings(NetworkConfig).latency_ms == 50

    def start(self, run):
        from cosim.core.kernel import Stage

        run.kernel.every(1_000_000_000, self.tick, stage=Stage.CONTROL)

    def tick(self, now_ns):
        if self.fails and now_ns >= 2_000_000_000:
            raise RuntimeError("flaky sensor")

    def finish(self, run):
        return {}


def test_runs_failing_in_a_plugin_keep_their_traceback_and_the_study_exits_4(tmp_path):
    from cosim.core.registry import registered

    text = TINY.format(duration=4.0) + '"scenario.adapters" = ["flaky"]\n'
    with registered("cosim.adapters", "flaky", Flaky):
        done = cli("study", str(_study(tmp_path, text)), "--out", "out", "--workers", "1",
                   cwd=tmp_path)  # fmt: skip
    assert done.returncode == 4, done.stderr
    assert "cosim: 4 of 8 runs failed (4 in a plugin):" in done.stderr
    out = tmp_path / "out"
    results = pd.read_parquet(out / "results.parquet")
    failed = results[results["status"] == "error"]
    assert set(failed["network.latency_ms"]) == {50} and len(failed) == 4
    assert set(failed["failure_kind"]) == {"plugin"}
    assert failed["error"].str.contains("adapter 'flaky'").all()
    assert (failed["sim_time_s"] == 2.0).all()  # what ran is in the row
    for run_id in failed["run_id"]:
        trace = (out / "runs" / run_id / "failure.txt").read_text()
        assert "RuntimeError: flaky sensor" in trace
        assert (out / "runs" / run_id / "summary.json").is_file()

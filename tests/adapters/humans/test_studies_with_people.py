"""Studies among people: local worker processes and a threaded Dask worker agree."""

import json
import os
import subprocess
import sys
import time
from pathlib import Path

import pandas as pd
import pytest

from cosim.studies import load_study, run_study
from cosim.studies.worker import VOLATILE_METRICS

pytestmark = pytest.mark.slow

STUDY = """
[study]
name = "people"
scenario = "warehouse-humans"
seeds = 2
duration_s = 8.0
tables = ["humans"]  # only the runs with people have it

[grid]
"humans.workers" = [0, 6]

[overrides]
"record.messages" = false
"""


def _comparable(frame: pd.DataFrame) -> pd.DataFrame:
    frame = frame.drop(columns=[c for c in VOLATILE_METRICS if c in frame.columns])
    return frame.sort_values("run_id").reset_index(drop=True)


def _threaded_dask_worker(tmp_path: Path):
    """A real scheduler and ONE worker process with two threads: two SUMO runs at once."""
    bin_dir = Path(sys.executable).parent
    scheduler_file = tmp_path / "scheduler.json"
    env = {**os.environ, "DASK_DISTRIBUTED__WORKER__DAEMON": "False"}
    common = {"stdout": subprocess.DEVNULL, "stderr": subprocess.DEVNULL, "env": env}
    procs = [
        subprocess.Popen(
            [str(bin_dir / "dask"), "scheduler", "--host", "127.0.0.1", "--port", "0",
             "--no-dashboard", "--scheduler-file", str(scheduler_file)],
            **common,
        )
    ]  # fmt: skip
    deadline = time.monotonic() + 60
    while not scheduler_file.exists() and time.monotonic() < deadline:
        time.sleep(0.2)
    procs.append(
        subprocess.Popen(
            [str(bin_dir / "dask"), "worker", "--scheduler-file", str(scheduler_file),
             "--nworkers", "1", "--nthreads", "2", "--no-dashboard", "--host", "127.0.0.1"],
            **common,
        )
    )  # fmt: skip
    return json.loads(scheduler_file.read_text())["address"], procs


def test_a_study_over_worker_counts_gives_the_same_rows_locally_and_on_a_threaded_dask_worker(
    tmp_path,
):
    path = tmp_path / "people.toml"
    path.write_text(STUDY)
    spec = load_study(path)
    local = run_study(spec, tmp_path / "local", workers=2)
    assert set(local["status"]) == {"ok"}
    assert set(local["humans.workers"]) == {0, 6}
    with_people = local[local["humans.workers"] == 6]
    assert (with_people["humans_seen"] == 6).all()
    assert local[local["humans.workers"] == 0]["humans_seen"].isna().all()  # SUMO not started
    for run_id, workers in zip(local["run_id"], local["humans.workers"], strict=True):
        kept = tmp_path / "local" / "runs" / run_id / "tables" / "humans.parquet"
        assert kept.is_file() == (workers == 6)
    address, procs = _threaded_dask_worker(tmp_path)
    try:
        from distributed import Client

        with Client(address, timeout="30s") as client:
            client.wait_for_workers(1, timeout=60)
        remote = run_study(spec, tmp_path / "dask", scheduler=address)
    finally:
        for proc in reversed(procs):
            proc.terminate()
        for proc in procs:
            try:
                proc.wait(timeout=20)
            except subprocess.TimeoutExpired:
                proc.kill()
    assert set(remote["status"]) == {"ok"}, remote["error"].tolist()
    pd.testing.assert_frame_equal(_comparable(local), _comparable(remote))

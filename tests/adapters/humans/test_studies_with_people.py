"""Studies among people: local worker processes and a threaded Dask worker agree."""

import pandas as pd
import pytest

from cosim.studies import load_study, run_study
from cosim.studies.worker import VOLATILE_METRICS
from tests.dask_cluster import dask_cluster

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


@pytest.mark.slow
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
    # ONE worker process with two threads: two SUMO runs at once in it
    with dask_cluster(tmp_path, workers=1, threads=2) as cluster:
        remote = run_study(spec, tmp_path / "dask", scheduler=cluster.address)
    assert set(remote["status"]) == {"ok"}, remote["error"].tolist()
    pd.testing.assert_frame_equal(_comparable(local), _comparable(remote))

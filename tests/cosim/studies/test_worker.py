"""One run of a study in a worker: plain data in, plain data out, failures as rows."""

import io
import json
import os
import signal
import threading
import time

import pandas as pd
import pytest

from cosim.studies.lifeline import StudyStopped, stop_on_signals
from cosim.studies.worker import Job, failed, job_scenario, row_cells, run_one, run_overrides


def _job(**changes):
    fields = dict(
        run_id="r0",
        scenario="warehouse-random",
        seed=3,
        duration_s=2.0,
        overrides={"robots.count": 2, "world.size_m": [30.0, 20.0]},
        tables=("poses",),
    )
    fields.update(changes)
    return Job(**fields)


def test_the_study_sets_seed_and_duration_beside_the_combination():
    overrides = run_overrides({"robots.count": 4}, seed=7, duration_s=5.0)
    assert overrides == {"robots.count": 4, "scenario.seed": 7, "scenario.duration_s": 5.0}
    assert run_overrides({"robots.count": 4}, seed=None, duration_s=None) == {"robots.count": 4}


def test_a_jobs_scenario_is_the_preset_with_its_overrides_seed_and_duration():
    scenario = job_scenario(_job())
    assert scenario.seed == 3
    assert scenario.robots.count == 2
    assert scenario.scenario.duration_s == 2.0
    assert tuple(scenario.world.size_m) == (30.0, 20.0)


def test_list_valued_overrides_become_their_json_text_in_the_row():
    row = row_cells(_job())
    assert row == {"run_id": "r0", "seed": 3, "robots.count": 2, "world.size_m": "[30.0, 20.0]"}
    assert json.loads(row["world.size_m"]) == [30.0, 20.0]


def test_a_run_returns_its_row_its_resolved_scenario_and_only_the_tables_asked_for():
    outcome = run_one(_job())
    assert outcome.row["status"] == "ok" and outcome.row["error"] == ""
    assert outcome.row["sim_time_s"] == 2.0
    assert outcome.row["wall_time_s"] == outcome.summary["wall_time_s"]
    assert "scenario" not in outcome.row  # the study's own columns say which
    assert "plugins" not in outcome.row and outcome.summary["plugins"][0]["package"] == "cosim"
    assert "seed = 3" in outcome.scenario_toml
    assert set(outcome.tables) == {"poses"}
    poses = pd.read_parquet(io.BytesIO(outcome.tables["poses"]))
    assert set(poses["robot"]) == {"robot_1", "robot_2"}  # robots are named from 1


def test_a_run_that_cannot_load_comes_back_as_an_error_row_naming_the_key():
    outcome = run_one(_job(overrides={"robots.count": -1}))
    assert outcome.row["status"] == "error"
    assert "robots.count" in outcome.row["error"]
    assert outcome.scenario_toml == "" and outcome.tables == {}


def test_a_failed_outcome_keeps_the_jobs_cells_and_the_time_it_took():
    outcome = failed(_job(), "it broke", 1.23456)
    assert outcome.row["run_id"] == "r0" and outcome.row["robots.count"] == 2
    assert outcome.row["status"] == "error" and outcome.row["error"] == "it broke"
    assert outcome.row["wall_time_s"] == 1.2346


def test_a_signal_during_a_run_of_the_study_process_ends_the_run_then_stops_the_study():
    sender = threading.Timer(0.5, os.kill, (os.getpid(), signal.SIGTERM))
    started = time.monotonic()
    with pytest.raises(StudyStopped) as stopped, stop_on_signals() as request:
        sender.start()
        run_one(_job(duration_s=1e5), stop=request)  # hours of wall time, left to run
    assert stopped.value.signum == signal.SIGTERM
    assert time.monotonic() - started < 30  # stopped at an event boundary, not at the end


def test_a_study_asked_to_stop_starts_no_run():
    with pytest.raises(StudyStopped), stop_on_signals() as request:
        request.signum = signal.SIGHUP
        run_one(_job(), stop=request)

"""Writing a study's folder: each run whole or not at all, and nothing of the user's touched."""

import io
import json

import pandas as pd
import pytest

from cosim.core.errors import ExportError
from cosim.runner.runfolder import RUN_FORMAT
from cosim.studies.folder import FolderState
from cosim.studies.worker import Outcome
from cosim.studies.writing import prepare, write_results, write_run
from tests.cosim.studies.small import on_its_way


def _outcome(run_id="0000_s1", status="ok"):
    buffer = io.BytesIO()
    pd.DataFrame({"t_s": [0.0, 1.0]}).to_parquet(buffer, index=False)
    row = {"run_id": run_id, "seed": 1, "status": status}
    summary = {"scenario": "small", "seed": 1}
    return Outcome(row, "# resolved\n", summary, {"poses": buffer.getvalue()})


def _users_files(out):
    """Files a user keeps in and beside a study folder under names cosim once used."""
    mine = {
        out / "plan.json.partial": "mine",
        out / "results.parquet.partial": "mine",
        out / "runs" / "0000_s1.partial" / "notes.txt": "mine",
        out / "runs" / "0000_s2.partial" / "row.json": "{}",
    }
    for path, text in mine.items():
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text)
    return mine


def test_a_run_folder_is_whole_of_format_1_and_leaves_nothing_on_its_way(tmp_path):
    prepare(tmp_path, FolderState(frozenset(), (), "{}"))
    write_run(tmp_path, _outcome())
    run = tmp_path / "runs" / "0000_s1"
    assert sorted(p.name for p in run.iterdir()) == [
        "row.json",
        "scenario.toml",
        "summary.json",
        "tables",
    ]
    assert json.loads((run / "summary.json").read_text()) == {
        "format": RUN_FORMAT,
        "scenario": "small",
        "seed": 1,
    }
    assert not [p for p in (tmp_path / "runs").iterdir() if on_its_way(p)]


def test_files_of_the_user_under_names_cosim_once_used_are_never_touched(tmp_path):
    mine = _users_files(tmp_path)
    prepare(tmp_path, FolderState(frozenset(), (), "{}"))
    write_run(tmp_path, _outcome())
    write_results(pd.DataFrame({"run_id": ["0000_s1"]}), tmp_path / "results.parquet")
    assert {path: path.read_text() for path in mine} == mine
    assert (tmp_path / "plan.json").read_text() == "{}"


def test_a_run_again_replaces_the_folder_a_study_wrote_for_it(tmp_path):
    write_run(tmp_path, _outcome(status="error"))
    write_run(tmp_path, _outcome(status="ok"))
    row = json.loads((tmp_path / "runs" / "0000_s1" / "row.json").read_text())
    assert row["status"] == "ok"
    assert [p.name for p in (tmp_path / "runs").iterdir()] == ["0000_s1"]


def test_a_folder_no_study_wrote_in_a_runs_place_is_named_and_left_alone(tmp_path):
    theirs = tmp_path / "runs" / "0000_s1"
    theirs.mkdir(parents=True)
    (theirs / "notes.txt").write_text("mine")
    with pytest.raises(ExportError) as refused:
        write_run(tmp_path, _outcome())
    assert str(refused.value) == (
        f"{theirs}: holds no row.json, so no study wrote it, where this run's folder goes; "
        "move it away, then continue with --resume"
    )
    assert [p.name for p in theirs.iterdir()] == ["notes.txt"]
    assert [p.name for p in (tmp_path / "runs").iterdir()] == ["0000_s1"]


def test_preparing_clears_only_runs_cut_short_on_their_way(tmp_path):
    mine = _users_files(tmp_path)
    stale = tmp_path / "runs" / ".cosim-partial-a1b2c3d4"
    stale.mkdir()
    (stale / "row.json").write_text("{}")
    prepare(tmp_path, FolderState(frozenset(), (), "{}"))
    assert not stale.exists()
    assert {path: path.read_text() for path in mine} == mine


def test_a_grid_over_values_of_two_kinds_is_written_as_their_toml_text(tmp_path):
    # a study over navigation.robots_layer = ["auto", false]: Parquet holds one type per column
    frame = pd.DataFrame(
        {"navigation.robots_layer": ["auto", False, None], "seed": [1, 2, 3], "x": [0.5, 1, 2]}
    )
    write_results(frame, tmp_path / "results.parquet")
    back = pd.read_parquet(tmp_path / "results.parquet")
    layer = back["navigation.robots_layer"]
    assert layer[:2].tolist() == ["auto", "false"] and layer.isna()[2]
    assert back["seed"].tolist() == [1, 2, 3] and back["x"].tolist() == [0.5, 1.0, 2.0]


def test_a_column_of_one_kind_is_written_as_it_is(tmp_path):
    frame = pd.DataFrame({"navigation.robots_layer": [True, False], "name": ["a", "b"]})
    write_results(frame, tmp_path / "results.parquet")
    back = pd.read_parquet(tmp_path / "results.parquet")
    assert back["navigation.robots_layer"].tolist() == [True, False]

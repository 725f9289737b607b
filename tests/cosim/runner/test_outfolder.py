"""--force replaces what an earlier run wrote, and nothing of the user's; where results go."""

import errno
import json
import os
import tempfile

import numpy as np
import pandas as pd
import pytest

import cosim
from cosim.core.errors import ExportError
from cosim.runner.outfolder import default_out, prepare_out, write_run
from cosim.runner.result import RunResult
from cosim.runner.runfolder import MARKER, RUN_FORMAT, is_cosim_folder, mark
from cosim.runner.staging import STAGING_PREFIX
from tests.folders import another_device, cannot_write, read_only_parent, tiny_disk

EARLIER = [
    "summary.json",
    "scenario.toml",
    "tables/poses.parquet",
    "tables/map_merges.parquet",
    "bag/metadata.yaml",
    "bag/bag.mcap",
    "maps/fleet.yaml",
    "maps/fleet.pgm",
    "maps/robot_12.pgm",
    "figures/trajectories.png",
    "figures/run.gif",
    "sumo/humans.sumocfg",
]
"""Files an earlier run wrote."""
USERS = [
    "notes.txt",
    "tables/mine.parquet",
    "tables/notes.txt",
    "maps/office.yaml",
    "figures/poster.png",
    "sumo/README",
    "analysis/poses.parquet",
]
"""Files the user put there."""
UNTABLED = [f for f in EARLIER if not f.startswith("tables/")]
"""An earlier run's files but its tables (whose names need every adapter imported)."""


def _folder(tmp_path, files, *, marked=True):
    """A folder holding ``files`` (each its own name as text), marked as a run folder."""
    out = tmp_path / "run"
    out.mkdir()
    if marked:
        mark(out)
    for relative in files:
        (out / relative).parent.mkdir(parents=True, exist_ok=True)
        (out / relative).write_text(relative)
    return out


def _files(out):
    """The files in ``out``, but cosim's mark, by path relative to it."""
    return sorted(
        str(p.relative_to(out)) for p in out.rglob("*") if p.is_file() and p.name != MARKER
    )


@pytest.mark.slow  # the table names come from every installed adapter (imported: 0.5 s)
def test_force_removes_an_earlier_runs_files_and_keeps_every_other(tmp_path):
    out = _folder(tmp_path, EARLIER + USERS)
    prepare_out(out, force=True, figures=True)
    assert _files(out) == sorted(USERS)
    assert not (out / "bag").exists()  # rosbags creates it afresh
    assert all((out / relative).read_text() == relative for relative in USERS)


def test_force_keeps_the_figures_when_the_run_does_not_draw_them(tmp_path):
    out = _folder(tmp_path, UNTABLED)
    prepare_out(out, force=True)
    figures = ["figures/run.gif", "figures/trajectories.png"]
    assert _files(out) == figures
    assert all((out / relative).read_text() == relative for relative in figures)


def test_force_removes_the_earlier_figures_when_the_run_draws_its_own(tmp_path):
    out = _folder(tmp_path, [*UNTABLED, "figures/poster.png"])
    prepare_out(out, force=True, figures=True)
    assert _files(out) == ["figures/poster.png"]


def test_a_file_named_figures_is_in_the_way_only_of_a_run_that_draws(tmp_path):
    out = _folder(tmp_path, ["summary.json", "figures"])
    with pytest.raises(ExportError, match=r"figures: is a file where a run writes its figures/"):
        prepare_out(out, force=True, figures=True)
    assert (out / "summary.json").exists()
    prepare_out(out, force=True)
    assert sorted(p.name for p in out.iterdir()) == [MARKER, "figures"]


def test_the_default_folder_is_taken_when_free_and_numbered_when_it_holds_a_run(tmp_path):
    base = tmp_path / "runs" / "warehouse-random-seed1"
    assert default_out(base) == base and base.is_dir()
    assert default_out(base) == base  # still empty: nothing to collide with
    (base / "summary.json").write_text("{}")
    second = default_out(base)
    assert second == tmp_path / "runs" / "warehouse-random-seed1-2" and second.is_dir()
    (second / "summary.json").write_text("{}")
    (tmp_path / "runs" / "warehouse-random-seed1-3").write_text("a file, not a folder")
    assert default_out(base) == tmp_path / "runs" / "warehouse-random-seed1-4"
    assert (base / "summary.json").read_text() == "{}"


def test_a_default_folder_that_cannot_be_made_is_named_in_one_line(tmp_path):
    (tmp_path / "runs").write_text("a file where the runs folder goes")
    with pytest.raises(ExportError) as refused:
        default_out(tmp_path / "runs" / "warehouse-random-seed1")
    assert str(refused.value) == (
        f"{tmp_path}/runs/warehouse-random-seed1: cannot make the results folder (Not a directory)"
    )


def test_without_force_nothing_is_removed_and_the_flag_is_named(tmp_path):
    out = _folder(tmp_path, EARLIER)
    with pytest.raises(ExportError, match=r"folder is not empty; not overwriting \(use --force\)"):
        prepare_out(out, force=False)
    assert all((out / relative).exists() for relative in EARLIER)


def test_a_stranger_in_the_bag_folder_is_named_and_nothing_is_removed(tmp_path):
    out = _folder(tmp_path, [*UNTABLED, "bag/readme.txt"])
    with pytest.raises(ExportError) as refused:
        prepare_out(out, force=True)
    assert str(refused.value) == (
        f"{out}/bag: holds 'readme.txt', which no run writes, and a new bag needs the folder "
        "to itself; move it away or choose another --out"
    )
    assert all((out / relative).exists() for relative in UNTABLED)


def test_a_stranger_in_the_bag_folder_stays_when_the_run_writes_no_bag(tmp_path):
    out = _folder(tmp_path, [*UNTABLED, "bag/readme.txt"])
    prepare_out(out, force=True, bag=False)
    assert [p.name for p in (out / "bag").iterdir()] == ["readme.txt"]


@pytest.mark.parametrize(
    ("blocker", "expected"),
    [
        ("summary.json/x", "summary.json: is a folder where a run writes its summary.json"),
        ("tables", "tables: is a file where a run writes its tables/ folder"),
    ],
)
def test_a_file_in_the_way_of_the_results_is_named_not_removed(tmp_path, blocker, expected):
    out = _folder(tmp_path, ["scenario.toml", blocker])
    with pytest.raises(ExportError, match=expected):
        prepare_out(out, force=True)
    assert (out / "scenario.toml").exists()


def test_a_file_where_the_folder_goes_is_refused_in_one_line(tmp_path):
    (tmp_path / "taken").write_text("a file")
    with pytest.raises(ExportError, match=r"taken: exists and is not a folder"):
        prepare_out(tmp_path / "taken", force=True)


@pytest.mark.slow  # as above
def test_written_results_join_the_users_files_in_the_same_folders(small_scenario, tmp_path):
    out = _folder(tmp_path, ["tables/mine.parquet", "tables/poses.parquet"])
    prepare_out(out, force=True)
    poses = pd.DataFrame({"t_s": [0.0, 0.1]})
    result = RunResult(small_scenario, {"scenario": "x"}, {"poses": poses})
    write_run(result, out)
    assert sorted(p.name for p in (out / "tables").iterdir()) == ["mine.parquet", "poses.parquet"]
    pd.testing.assert_frame_equal(pd.read_parquet(out / "tables" / "poses.parquet"), poses)
    assert not (tmp_path / "run.partial").exists()
    assert cosim.load_scenario(out / "scenario.toml") == small_scenario


# --- where the results go, and what is never touched ------------------------------------------


def _result(scenario):
    """A run's result with a small poses table and a summary."""
    poses = pd.DataFrame({"t_s": [0.0, 0.1], "robot": ["robot_1"] * 2})
    return RunResult(scenario, {"scenario": "x", "sim_time_s": 0.1}, {"poses": poses})


def _whole(out):
    """Assert ``out`` holds a whole run (format 1, marked) and no staging folder."""
    assert json.loads((out / "summary.json").read_text()) == {
        "format": RUN_FORMAT,
        "scenario": "x",
        "sim_time_s": 0.1,
    }
    assert len(pd.read_parquet(out / "tables" / "poses.parquet")) == 2
    assert (out / "scenario.toml").is_file() and (out / MARKER).is_file()
    assert [p.name for p in out.iterdir() if p.name.startswith(STAGING_PREFIX)] == []


def _write(scenario, out):
    prepare_out(out, force=False, bag=False)
    write_run(_result(scenario), out)


def test_summary_json_begins_with_the_format_and_the_folder_is_marked(small_scenario, tmp_path):
    out = tmp_path / "run"
    _write(small_scenario, out)
    assert next(iter(json.loads((out / "summary.json").read_text()))) == "format"
    _whole(out)
    assert is_cosim_folder(out)


def test_an_out_linked_to_another_folder_takes_the_whole_run(small_scenario, tmp_path):
    (tmp_path / "elsewhere" / "res").mkdir(parents=True)
    (tmp_path / "res").symlink_to(tmp_path / "elsewhere" / "res")
    _write(small_scenario, tmp_path / "res")
    _whole(tmp_path / "elsewhere" / "res")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["elsewhere", "res"]


def test_an_out_linked_to_another_device_takes_the_whole_run(small_scenario, tmp_path):
    with another_device(tmp_path) as device:
        (tmp_path / "res").symlink_to(device)
        assert device.stat().st_dev != tmp_path.stat().st_dev  # a rename beside res fails
        _write(small_scenario, tmp_path / "res")
        _whole(device)
    assert [p.name for p in tmp_path.iterdir()] == ["res"]


def test_a_tables_folder_linked_to_another_device_is_copied_into(small_scenario, tmp_path):
    out = tmp_path / "run"
    out.mkdir()
    with another_device(tmp_path) as device:
        (out / "tables").symlink_to(device)
        (device / "mine.parquet").write_text("mine")
        write_run(_result(small_scenario), out)
        assert sorted(p.name for p in device.iterdir()) == ["mine.parquet", "poses.parquet"]
        assert (device / "mine.parquet").read_text() == "mine"
        assert len(pd.read_parquet(out / "tables" / "poses.parquet")) == 2
        assert (out / "tables").is_symlink()


def test_a_writable_out_in_a_read_only_folder_takes_the_whole_run(small_scenario, tmp_path):
    with read_only_parent(tmp_path) as out:
        assert cannot_write(out.parent) and not cannot_write(out)
        _write(small_scenario, out)
        _whole(out)


def test_a_file_named_out_partial_is_left_as_it_is(small_scenario, tmp_path):
    (tmp_path / "res.partial").write_text("mine")
    _write(small_scenario, tmp_path / "res")
    _whole(tmp_path / "res")
    assert (tmp_path / "res.partial").read_text() == "mine"


def test_a_users_folder_named_res_partial_survives_untouched(small_scenario, tmp_path):
    mine = tmp_path / "res.partial"
    (mine / "data").mkdir(parents=True)
    (mine / "data" / "notes.txt").write_text("mine")
    _write(small_scenario, tmp_path / "res")
    _whole(tmp_path / "res")
    assert [str(p.relative_to(mine)) for p in sorted(mine.rglob("*"))] == [
        "data",
        "data/notes.txt",
    ]
    assert (mine / "data" / "notes.txt").read_text() == "mine"


def _full_for(out, monkeypatch):
    """Writing a table under ``out`` fails with ENOSPC (where no small disk can be mounted)."""
    real = pd.DataFrame.to_parquet

    def full(frame, path, *args, **kwargs):
        if str(path).startswith(str(out)):
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), str(path))
        return real(frame, path, *args, **kwargs)

    monkeypatch.setattr(pd.DataFrame, "to_parquet", full)


def test_a_folder_too_full_for_the_results_leaves_them_whole_in_a_spare_folder(
    small_scenario, tmp_path, monkeypatch
):
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path / "spare"))
    (tmp_path / "spare").mkdir()
    big = {"poses": pd.DataFrame({"t_s": np.arange(100_000, dtype=float)})}
    result = RunResult(small_scenario, {"scenario": "x", "sim_time_s": 0.1}, big)
    with tiny_disk(tmp_path, 64) as disk:
        out = (disk or tmp_path) / "run"
        if disk is None:
            _full_for(out, monkeypatch)
        prepare_out(out, force=False, bag=False)
        with pytest.raises(ExportError) as refused:
            write_run(result, out)
        assert [p.name for p in out.iterdir()] == [MARKER]  # nothing half-written
    (kept,) = (tmp_path / "spare").iterdir()
    said = str(refused.value)  # pyarrow words the full disk its own way
    assert said.startswith(f"{out}: cannot write results (") and "No space left on device" in said
    assert said.endswith(f"; they are kept in {kept}/ instead")
    assert refused.value.kept is result and result.out == kept
    assert len(pd.read_parquet(kept / "tables" / "poses.parquet")) == 100_000
    assert json.loads((kept / "summary.json").read_text())["format"] == RUN_FORMAT


def test_results_that_fit_nowhere_say_so_and_leave_nothing_half_written(
    small_scenario, tmp_path, monkeypatch
):
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path / "spare"))
    (tmp_path / "spare").mkdir()
    _full_for(tmp_path, monkeypatch)
    out = tmp_path / "run"
    prepare_out(out, force=False, bag=False)
    with pytest.raises(ExportError) as refused:
        write_run(_result(small_scenario), out)
    assert str(refused.value) == (
        f"{out}: cannot write results (No space left on device); no copy could be kept"
    )
    assert [p.name for p in out.iterdir()] == [MARKER]
    assert list((tmp_path / "spare").iterdir()) == []


def test_results_that_cannot_take_their_places_stay_whole_in_the_staging_folder(
    small_scenario, tmp_path
):
    out = tmp_path / "run"
    prepare_out(out, force=False, bag=False)
    (out / "tables").write_text("a file where the tables go")
    with pytest.raises(ExportError) as refused:
        write_run(_result(small_scenario), out)
    (stage,) = [p for p in out.iterdir() if p.name.startswith(STAGING_PREFIX)]
    assert str(refused.value) == (
        f"{out}: cannot put the results in place ({out}/tables: is a file where the results "
        f"have a folder); those not in place are in {stage}/"
    )
    assert len(pd.read_parquet(stage / "tables" / "poses.parquet")) == 2
    assert (stage / "summary.json").is_file() and not (out / "summary.json").exists()
    assert (out / "tables").read_text() == "a file where the tables go"


# --- --force only in a folder cosim wrote -----------------------------------------------------


def test_force_refuses_a_folder_cosim_did_not_write_and_removes_nothing(tmp_path):
    out = _folder(tmp_path, [*UNTABLED, "notes.txt"], marked=False)
    with pytest.raises(ExportError) as refused:
        prepare_out(out, force=True)
    assert str(refused.value) == (
        f"{out}: not a run folder (no .cosim-run, nor the summary.json and scenario.toml of a "
        "run): --force replaces only an earlier run's files; choose another --out"
    )
    assert _files(out) == sorted([*UNTABLED, "notes.txt"])
    assert not (out / MARKER).exists()


def test_force_replaces_a_run_folder_written_before_folders_were_marked(tmp_path):
    out = _folder(tmp_path, UNTABLED, marked=False)
    summary = {"scenario": "x", "seed": 1, "version": "0.1.0", "sim_time_s": 1.0}
    (out / "summary.json").write_text(json.dumps(summary))
    prepare_out(out, force=True)
    assert _files(out) == ["figures/run.gif", "figures/trajectories.png"]
    assert is_cosim_folder(out) and (out / MARKER).is_file()


def test_force_refuses_a_later_run_folder_whose_mark_was_removed(tmp_path):
    out = _folder(tmp_path, UNTABLED, marked=False)
    summary = {"format": 1, "scenario": "x", "seed": 1, "version": "0.1.0", "sim_time_s": 1.0}
    (out / "summary.json").write_text(json.dumps(summary))
    with pytest.raises(ExportError, match=r"not a run folder \(no \.cosim-run"):
        prepare_out(out, force=True)
    assert _files(out) == sorted(UNTABLED)


def test_force_clears_what_a_run_killed_outright_left_on_its_way(tmp_path):
    out = _folder(tmp_path, ["scenario.toml"])
    stale = out / f"{STAGING_PREFIX}abc123_x"
    (stale / "tables").mkdir(parents=True)
    (stale / "tables" / "poses.parquet").write_text("half")
    with pytest.raises(ExportError, match="not empty"):
        prepare_out(out, force=False)
    assert stale.is_dir()
    prepare_out(out, force=True)
    assert sorted(p.name for p in out.iterdir()) == [MARKER]


def test_a_folder_holding_only_the_mark_counts_as_empty(tmp_path):
    out = _folder(tmp_path, [])
    prepare_out(out, force=False)
    base = tmp_path / "runs" / "x-seed1"
    base.mkdir(parents=True)
    mark(base)
    assert default_out(base) == base

"""Putting results in place: inside the folder, across devices, never over another's file."""

import errno
import os

import pytest

import cosim.runner.staging as staging
from cosim.core.errors import ExportError
from cosim.runner.staging import (
    STAGING_PREFIX,
    is_staging,
    put_in_place,
    replace_file,
    spare_folder,
    stage_in,
    stale_stagings,
)
from tests.folders import another_device


def _staged(target):
    stage = stage_in(target)
    (stage / "tables").mkdir()
    (stage / "tables" / "poses.parquet").write_text("poses")
    (stage / "summary.json").write_text("{}")
    (stage / "scenario.toml").write_text("")
    return stage


def test_a_staging_folder_is_made_inside_the_folder_under_a_name_of_its_own(tmp_path):
    first, second = stage_in(tmp_path), stage_in(tmp_path)
    assert first != second and first.parent == tmp_path
    assert first.name.startswith(STAGING_PREFIX) and is_staging(first)
    assert stale_stagings(tmp_path) == sorted([first, second])


def test_only_cosims_own_names_count_as_staging(tmp_path):
    for name in ("res.partial", ".cosim-partial-", "cosim-partial-abc", ".cosim-partial-AB!"):
        (tmp_path / name).mkdir()
    (tmp_path / f"{STAGING_PREFIX}link").symlink_to(tmp_path / "res.partial")
    assert stale_stagings(tmp_path) == []


def test_every_file_takes_its_place_and_the_summary_comes_last(tmp_path, monkeypatch):
    target = tmp_path / "run"
    (target / "tables").mkdir(parents=True)
    (target / "tables" / "mine.parquet").write_text("mine")
    stage = _staged(target)
    moved = []
    real = os.replace
    monkeypatch.setattr(os, "replace", lambda a, b: (moved.append(os.path.basename(b)), real(a, b)))
    put_in_place(stage, target)
    assert moved[-1] == "summary.json"
    assert sorted(p.name for p in (target / "tables").iterdir()) == [
        "mine.parquet",
        "poses.parquet",
    ]
    assert [p for p in stage.rglob("*") if p.is_file()] == []


def test_a_folder_on_another_device_is_copied_into_file_by_file(tmp_path):
    target = tmp_path / "run"
    target.mkdir()
    with another_device(tmp_path) as device:
        (target / "tables").symlink_to(device)
        (device / "poses.parquet").write_text("earlier")
        stage = _staged(target)
        put_in_place(stage, target)
        assert (device / "poses.parquet").read_text() == "poses"
        assert [p.name for p in device.iterdir()] == ["poses.parquet"]  # nothing left beside
    assert (target / "summary.json").read_text() == "{}"


def test_a_rename_refused_for_another_reason_is_not_taken_for_another_device(tmp_path, monkeypatch):
    target = tmp_path / "run"
    target.mkdir()
    stage = _staged(target)

    def refused(a, b):
        raise OSError(errno.EACCES, os.strerror(errno.EACCES), b)

    monkeypatch.setattr(os, "replace", refused)
    with pytest.raises(PermissionError):
        put_in_place(stage, target)
    monkeypatch.undo()
    assert (stage / "summary.json").is_file()  # what was not moved stays whole


@pytest.mark.parametrize(
    ("blocker", "expected"),
    [("tables", "is a file where the results have a folder"),
     ("summary.json", "is a folder where the results have a file")],
)  # fmt: skip
def test_something_in_the_way_is_named_and_left_alone(tmp_path, blocker, expected):
    target = tmp_path / "run"
    target.mkdir()
    if blocker == "tables":
        (target / "tables").write_text("mine")
    else:
        (target / "summary.json").mkdir()
    stage = _staged(target)
    with pytest.raises(ExportError, match=f"{target / blocker}: {expected}"):
        put_in_place(stage, target)
    assert (stage / "summary.json").is_file()


def test_a_file_is_replaced_through_a_name_no_file_of_the_users_has(tmp_path):
    path = tmp_path / "results.parquet"
    (tmp_path / "results.parquet.partial").write_text("mine")
    replace_file(path, lambda beside: beside.write_text("new"))
    assert path.read_text() == "new"
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "results.parquet",
        "results.parquet.partial",
    ]
    assert (tmp_path / "results.parquet.partial").read_text() == "mine"


def test_a_file_that_fails_to_be_written_leaves_the_old_one_and_nothing_beside(tmp_path):
    path = tmp_path / "plan.json"
    path.write_text("old")

    def full(beside):
        beside.write_text("half")
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    with pytest.raises(OSError, match="No space left"):
        replace_file(path, full)
    assert [p.name for p in tmp_path.iterdir()] == ["plan.json"] and path.read_text() == "old"


def test_a_spare_folder_is_new_in_the_temporary_folder(tmp_path, monkeypatch):
    monkeypatch.setattr(staging.tempfile, "tempdir", str(tmp_path))
    first, second = spare_folder("run"), spare_folder("run")
    assert first != second and first.parent == second.parent == tmp_path
    assert first.name.startswith("cosim-run-")

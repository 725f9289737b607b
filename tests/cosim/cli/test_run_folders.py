"""`cosim run`'s folders: default ones that do not collide, --force that keeps the figures,
and every place an --out may be (another device, a read-only parent) keeping the whole run."""

import json

import pandas as pd
import pytest

from cosim.runner.runfolder import MARKER, RUN_FORMAT
from cosim.runner.staging import STAGING_PREFIX
from tests.conftest import cosim_main
from tests.folders import another_device, cannot_write, read_only_parent

SMALL = [
    *("--set", "world.size_m=[12.0, 12.0]"),
    *("--set", "world.shelf_count=4"),
    *("--set", "robots.count=3"),
    *("--set", "lidar.beams=90"),
    *("--set", "robots.driver=waypoints"),
    *("--duration-s", "1", "--bag", "none"),
]
"""A 1 s run of 3 robots in a 12 m hall, no bag: a fraction of a second."""
BASE = "runs/warehouse-random-seed1"


@pytest.mark.slow  # three short runs
def test_a_second_run_without_out_writes_to_a_numbered_folder_and_says_which(tmp_path):
    first = cosim_main("run", "warehouse-random", *SMALL, cwd=tmp_path)
    assert first.returncode == 0, first.stderr
    assert f"results: {BASE}/  (summary.json" in first.stdout
    assert "results folder" not in first.stdout
    second = cosim_main("run", "warehouse-random", *SMALL, cwd=tmp_path)
    assert second.returncode == 0, second.stderr
    assert second.stdout.splitlines()[0] == (
        f"results folder: {BASE}-2/ ({BASE}/ holds an earlier run; "
        "--out DIR chooses, --force replaces it)"
    )
    assert f"results: {BASE}-2/  (summary.json" in second.stdout
    assert (tmp_path / f"{BASE}-2" / "summary.json").is_file()
    quiet = cosim_main("run", "warehouse-random", *SMALL, "--quiet", cwd=tmp_path)
    assert quiet.returncode == 0 and quiet.stdout == "", quiet.stderr
    assert (tmp_path / f"{BASE}-3" / "summary.json").is_file()
    assert sorted(p.name for p in (tmp_path / "runs").iterdir()) == [
        "warehouse-random-seed1",
        "warehouse-random-seed1-2",
        "warehouse-random-seed1-3",
    ]


@pytest.mark.slow  # two short runs
def test_an_explicit_out_is_still_refused_when_it_holds_a_run(tmp_path):
    args = ("run", "warehouse-random", *SMALL, "--out", "mine", "--quiet")
    assert cosim_main(*args, cwd=tmp_path).returncode == 0
    refused = cosim_main(*args, cwd=tmp_path)
    assert refused.returncode == 2
    assert refused.stderr == (
        "cosim: error: mine: folder is not empty; not overwriting (use --force)\n"
    )
    assert sorted(p.name for p in tmp_path.iterdir()) == ["mine"]


@pytest.mark.slow  # two short runs
def test_force_without_figures_keeps_the_figures_a_user_drew_and_says_whose_they_are(tmp_path):
    args = ("run", "warehouse-random", *SMALL, "--out", "runs/demo", "--force")
    assert cosim_main(*args, cwd=tmp_path).returncode == 0
    figures = tmp_path / "runs" / "demo" / "figures"
    figures.mkdir()
    (figures / "trajectories.png").write_bytes(b"drawn by cosim plot")
    again = cosim_main(*args, cwd=tmp_path)
    assert again.returncode == 0, again.stderr
    assert (figures / "trajectories.png").read_bytes() == b"drawn by cosim plot"
    assert again.stdout.splitlines()[-1] == (
        "figures/: kept from before, not of this run (`cosim plot runs/demo` redraws them)"
    )


def _kept_everything(folder, *, bag=False):
    """Assert ``folder`` holds the whole of a 1 s run: summary, scenario, tables (and bag)."""
    summary = json.loads((folder / "summary.json").read_text())
    assert summary["format"] == RUN_FORMAT and summary["sim_time_s"] == 1.0
    assert (folder / "scenario.toml").is_file() and (folder / MARKER).is_file()
    assert len(pd.read_parquet(folder / "tables" / "poses.parquet")) > 0
    assert (folder / "bag" / "metadata.yaml").is_file() == bag
    assert not [p for p in folder.iterdir() if p.name.startswith(STAGING_PREFIX)]


@pytest.mark.slow  # a short run
def test_a_run_whose_out_links_to_another_device_keeps_everything(tmp_path):
    with another_device(tmp_path) as device:
        (tmp_path / "res").symlink_to(device)
        args = ("run", "warehouse-random", *SMALL, "--bag", "mcap", "--out", "res", "--quiet")
        done = cosim_main(*args, cwd=tmp_path)
        assert done.returncode == 0, done.stderr
        _kept_everything(device, bag=True)
    assert [p.name for p in tmp_path.iterdir()] == ["res"]


@pytest.mark.slow  # a short run
def test_a_run_into_a_writable_folder_in_a_read_only_one_keeps_everything(tmp_path):
    with read_only_parent(tmp_path) as out:
        assert cannot_write(out.parent)
        done = cosim_main("run", "warehouse-random", *SMALL, "--out", str(out), "--quiet")
        assert done.returncode == 0, done.stderr
        _kept_everything(out)


@pytest.mark.slow  # a short run
def test_a_run_leaves_a_file_out_partial_and_a_users_folder_res_partial_untouched(tmp_path):
    (tmp_path / "res.partial").mkdir()
    (tmp_path / "res.partial" / "notes.txt").write_text("mine")
    (tmp_path / "other.partial").write_text("mine too")
    for out in ("res", "other"):
        done = cosim_main("run", "warehouse-random", *SMALL, "--out", out, "--quiet", cwd=tmp_path)
        assert done.returncode == 0, done.stderr
        _kept_everything(tmp_path / out)
    assert (tmp_path / "res.partial" / "notes.txt").read_text() == "mine"
    assert [p.name for p in (tmp_path / "res.partial").iterdir()] == ["notes.txt"]
    assert (tmp_path / "other.partial").read_text() == "mine too"


@pytest.mark.slow  # a short run
def test_force_into_a_folder_cosim_did_not_write_is_refused_in_one_line(tmp_path):
    mine = tmp_path / "thesis"
    (mine / "tables").mkdir(parents=True)
    (mine / "tables" / "poses.parquet").write_text("my own poses")
    (mine / "summary.json").write_text("{}")
    done = cosim_main("run", "warehouse-random", *SMALL, "--out", "thesis", "--force", cwd=tmp_path)
    assert done.returncode == 2
    assert done.stderr == (
        "cosim: error: thesis: not a run folder (no .cosim-run, nor the summary.json and "
        "scenario.toml of a run): --force replaces only an earlier run's files; choose another "
        "--out\n"
    )
    assert (mine / "tables" / "poses.parquet").read_text() == "my own poses"
    assert sorted(p.name for p in mine.iterdir()) == ["summary.json", "tables"]

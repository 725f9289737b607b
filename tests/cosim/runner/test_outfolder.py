"""--force replaces what an earlier run wrote, and nothing of the user's; default folders."""

import pandas as pd
import pytest

import cosim
from cosim.core.errors import ExportError
from cosim.runner.outfolder import default_out, prepare_out, write_run
from cosim.runner.result import RunResult

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


def _folder(tmp_path, files):
    out = tmp_path / "run"
    for relative in files:
        (out / relative).parent.mkdir(parents=True, exist_ok=True)
        (out / relative).write_text(relative)
    return out


@pytest.mark.slow  # the table names come from every installed adapter (imported: 0.5 s)
def test_force_removes_an_earlier_runs_files_and_keeps_every_other(tmp_path):
    out = _folder(tmp_path, EARLIER + USERS)
    prepare_out(out, force=True, figures=True)
    assert sorted(str(p.relative_to(out)) for p in out.rglob("*") if p.is_file()) == sorted(USERS)
    assert not (out / "bag").exists()  # rosbags creates it afresh
    assert all((out / relative).read_text() == relative for relative in USERS)


def test_force_keeps_the_figures_when_the_run_does_not_draw_them(tmp_path):
    out = _folder(tmp_path, UNTABLED)
    prepare_out(out, force=True)
    figures = ["figures/run.gif", "figures/trajectories.png"]
    assert sorted(str(p.relative_to(out)) for p in out.rglob("*") if p.is_file()) == figures
    assert all((out / relative).read_text() == relative for relative in figures)


def test_force_removes_the_earlier_figures_when_the_run_draws_its_own(tmp_path):
    out = _folder(tmp_path, [*UNTABLED, "figures/poster.png"])
    prepare_out(out, force=True, figures=True)
    assert [str(p.relative_to(out)) for p in out.rglob("*") if p.is_file()] == [
        "figures/poster.png"
    ]


def test_a_file_named_figures_is_in_the_way_only_of_a_run_that_draws(tmp_path):
    out = _folder(tmp_path, ["summary.json", "figures"])
    with pytest.raises(ExportError, match=r"figures: is a file where a run writes its figures/"):
        prepare_out(out, force=True, figures=True)
    assert (out / "summary.json").exists()
    prepare_out(out, force=True)
    assert [p.name for p in out.iterdir()] == ["figures"]


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

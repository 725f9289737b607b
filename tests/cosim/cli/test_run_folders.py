"""`cosim run`'s folders: default ones that do not collide, --force that keeps the figures."""

import pytest

from tests.conftest import cosim_main

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

"""`cosim map RUN_DIR`: a run folder of an earlier format, and whose folder --out is."""

import json
import shutil
from pathlib import Path

import pytest

from cosim.runner.runfolder import MARKER
from cosim.runner.staging import STAGING_PREFIX
from tests.conftest import REPO, SMALL, cosim_main

_cli = cosim_main

OLD_RUN = REPO / "tests" / "oldruns" / "before-462a048"
"""A run written at 462a048^ (format 0), kept without its bag (tests/oldruns/README.md)."""
ROBOT_1 = ("--scan", "/robot_1/scan", "--odom", "/robot_1/odom")


@pytest.fixture(scope="module")
def old_run(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, int]:
    """A copy of the format-0 run with a bag of the same run recorded now; its messages.

    The bag's format (MCAP) is the same then and now, so the project keeps no recorded bag:
    what is of an earlier format is the folder around it.
    """
    root = tmp_path_factory.mktemp("oldrun")
    old = root / "before-462a048"
    shutil.copytree(OLD_RUN, old)
    fresh = root / "fresh"
    sets = [f"--set={key}={json.dumps(value)}" for key, value in SMALL.items()]
    done = _cli("run", "warehouse-random", "--quiet", "--out", str(fresh), *sets)
    assert done.returncode == 0, done.stderr
    shutil.copytree(fresh / "bag", old / "bag")
    info = _cli("bag", "info", str(fresh / "bag"))
    messages = int(info.stdout.split("messages:", 1)[1].split()[0])
    return old, messages


def test_the_bag_of_a_run_of_an_earlier_format_is_mapped_from_its_folder(old_run, tmp_path):
    old, messages = old_run
    done = _cli("map", str(old), *ROBOT_1, "--out", str(tmp_path / "m"))
    assert done.returncode == 0, done.stderr
    assert done.stdout.startswith("30 scans, ")
    summary = json.loads((tmp_path / "m" / "summary.json").read_text())
    assert summary["scans"] == 30 and summary["map_updates"] >= 1
    assert (tmp_path / "m" / MARKER).read_text().startswith("cosim map folder")
    info = _cli("bag", "info", str(old))
    assert info.returncode == 0, info.stderr
    assert (
        f"bag:       {old / 'bag'}\n" in info.stdout and f"messages:  {messages}\n" in info.stdout
    )


def test_force_replaces_an_earlier_maps_files_and_nothing_else(old_run, tmp_path):
    old, _ = old_run
    out = tmp_path / "m"
    assert _cli("map", str(old), *ROBOT_1, "--out", str(out)).returncode == 0
    (out / "notes.txt").write_text("mine")
    (out / "map.png").write_text("replaced")
    again = _cli("map", str(old), *ROBOT_1, "--out", str(out), "--force")
    assert again.returncode == 0, again.stderr
    assert (out / "notes.txt").read_text() == "mine"
    assert (out / "map.png").read_bytes().startswith(b"\x89PNG")
    assert not [p for p in out.iterdir() if p.name.startswith(STAGING_PREFIX)]


def test_force_into_a_folder_no_cosim_map_wrote_is_refused_and_nothing_is_touched(
    old_run, tmp_path
):
    old, _ = old_run
    out = tmp_path / "mine"
    out.mkdir()
    (out / "map.png").write_text("my own map")
    done = _cli("map", str(old), *ROBOT_1, "--out", str(out), "--force")
    assert done.returncode == 2
    assert done.stderr == (
        f"cosim: error: {out}: not a folder of `cosim map` (no .cosim-run, nor its "
        "summary.json): --force replaces only an earlier map's files; choose another --out\n"
    )
    assert [p.name for p in out.iterdir()] == ["map.png"]
    assert (out / "map.png").read_text() == "my own map"

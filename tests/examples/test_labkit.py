"""The example plugin package, installed as a user would, used without editing cosim.

labkit (``examples/labkit``) is installed into a folder of its own (``pip install
--target``) and put on ``PYTHONPATH`` of the processes that use it: cosim's command line,
a study's local workers, a Dask cluster's workers. cosim's own environment stays as it is.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from importlib.metadata import version
from pathlib import Path

import pandas as pd
import pytest

from cosim.studies.worker import VOLATILE_METRICS
from tests.conftest import REPO
from tests.dask_cluster import dask_cluster

pytestmark = pytest.mark.slow

LABKIT = REPO / "examples" / "labkit"
SHORT = ["--duration-s", "30", "--set", "robots.driver=tasks"]


@pytest.fixture(scope="module")
def plugins(tmp_path_factory: pytest.TempPathFactory) -> dict[str, str]:
    """An environment with labkit installed (a folder on PYTHONPATH).

    Built from a copy: pip builds inside the source folder (``build/``, ``*.egg-info``), and
    two test workers installing from the same folder at once broke each other's build.
    """
    target = tmp_path_factory.mktemp("site")
    source = tmp_path_factory.mktemp("src") / "labkit"
    shutil.copytree(LABKIT, source, ignore=shutil.ignore_patterns("build", "*.egg-info"))
    subprocess.run(
        [sys.executable, "-m", "pip", "install", "--quiet", "--no-deps", "--no-build-isolation",
         "--target", str(target), str(source)],
        check=True, capture_output=True, timeout=300,
    )  # fmt: skip
    return {**os.environ, "PYTHONPATH": os.pathsep.join([str(target), str(REPO)])}


def cosim(
    env: dict[str, str], *args: str, cwd: Path | None = None
) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "cosim", *args],
        capture_output=True, text=True, env=env, cwd=cwd, timeout=600,
    )  # fmt: skip


def test_cosim_plugins_lists_labkits_protocol_controller_adapter_and_sections_beside_the_built_ins(
    plugins,
):
    done = cosim(plugins, "plugins")
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()

    def entry(name: str, package: str) -> bool:
        return any(line.split()[:2] == [name, package] for line in lines if line.startswith("  "))

    for name in ("sequential_auction", "pure_pursuit", "rangefinder"):
        assert entry(name, "labkit"), name
    for name in ("distributed_simplex", "dwa", "lidar", "astar", "pibt"):
        assert entry(name, "cosim"), name
    assert "BROKEN" not in done.stdout


def test_a_run_with_labkits_protocol_controller_and_sensor_repeats_exactly(plugins, tmp_path):
    args = [
        "run", "warehouse-random", *SHORT,
        "--set", "assignment.protocol=sequential_auction",
        "--set", "sequential_auction.settle_rounds=2",
        "--set", "navigation.controller=pure_pursuit",
        "--set", "pure_pursuit.cruise_mps=0.7",
        "--set", 'scenario.adapters=["rangefinder"]',
        "--set", 'record.topics=["*"]',
    ]  # fmt: skip
    first = cosim(plugins, *args, "--out", str(tmp_path / "a"))
    assert first.returncode == 0, first.stderr
    summary = json.loads((tmp_path / "a" / "summary.json").read_text())
    assert summary["tasks_completed"] >= 1
    assert summary["rangefinder_readings"] == 4 * 300  # 4 robots at 10 Hz for 30 s
    ranges = pd.read_parquet(tmp_path / "a" / "tables" / "ranges.parquet")
    assert list(ranges.columns) == ["t_s", "robot", "range_m"] and len(ranges) == 1200
    resolved = (tmp_path / "a" / "scenario.toml").read_text()
    assert "[sequential_auction]\nsettle_rounds = 2" in resolved
    assert "[pure_pursuit]\ncruise_mps = 0.7" in resolved
    assert f'[provenance]\ncosim = "{version("cosim")}"\nlabkit = "0.1.0"\n' in resolved
    used = {(p["group"], p["name"]): p["package"] for p in summary["plugins"]}
    for chosen in (
        ("cosim.protocols", "sequential_auction"),
        ("cosim.controllers", "pure_pursuit"),
        ("cosim.adapters", "rangefinder"),
        ("cosim.sections", "rangefinder"),
    ):
        assert used[chosen] == "labkit", chosen
    info = cosim(plugins, "bag", "info", str(tmp_path / "a" / "bag"))
    assert "sensor_msgs/msg/Range" in info.stdout
    assert "labkit_msgs/msg/BidTable" in info.stdout
    # the resolved scenario reproduces the run, tables and all
    again = cosim(
        plugins, "run", str(tmp_path / "a" / "scenario.toml"), "--out", str(tmp_path / "b")
    )
    assert again.returncode == 0, again.stderr
    assert "note:" not in again.stderr  # the same versions are installed
    for table in ("poses", "tasks", "assignments", "ranges", "navigation"):
        pd.testing.assert_frame_equal(
            pd.read_parquet(tmp_path / "a" / "tables" / f"{table}.parquet").drop(
                columns=["plan_ms"], errors="ignore"
            ),
            pd.read_parquet(tmp_path / "b" / "tables" / f"{table}.parquet").drop(
                columns=["plan_ms"], errors="ignore"
            ),
        )


@pytest.mark.parametrize(
    ("setting", "fragment"),
    [
        (
            "sequential_auction.settle_rounds=-1",
            "[sequential_auction] settle_rounds = -1: expected an integer >= 0 and <= 100",
        ),
        ("sequential_auction.settle=1", "unknown key 'settle'; did you mean 'settle_rounds'?"),
        ("pure_pursuit.cruise_mps=9", "[pure_pursuit] cruise_mps = 9: expected a number > 0"),
        ("navigation.controller=pure_persuit", "did you mean 'pure_pursuit'?"),
    ],
)
def test_a_plugins_settings_are_checked_like_the_built_ins(plugins, setting, fragment):
    done = cosim(plugins, "check", "warehouse-random", "--set", setting)
    assert done.returncode == 2
    assert fragment in done.stderr, done.stderr
    assert done.stderr.count("\n") == 1 and "Traceback" not in done.stderr


def test_the_example_study_gives_the_same_rows_on_two_local_workers_and_on_dask(plugins, tmp_path):
    local = cosim(plugins, "study", str(LABKIT / "study.toml"), "--out", str(tmp_path / "local"),
                  "--workers", "2")  # fmt: skip
    assert local.returncode == 0, local.stderr
    with dask_cluster(tmp_path, workers=2, env={"PYTHONPATH": plugins["PYTHONPATH"]}) as cluster:
        remote = cosim(plugins, "study", str(LABKIT / "study.toml"), "--out",
                       str(tmp_path / "dask"), "--scheduler", cluster.address)  # fmt: skip
    assert remote.returncode == 0, remote.stderr
    rows = [
        pd.read_parquet(tmp_path / folder / "results.parquet").sort_values("run_id")
        for folder in ("local", "dask")
    ]
    assert set(rows[0]["status"]) == {"ok"} and len(rows[0]) == 16
    assert set(rows[0]["assignment.protocol"]) == {"distributed_simplex", "sequential_auction"}
    volatile = [c for c in VOLATILE_METRICS if c in rows[0].columns]
    pd.testing.assert_frame_equal(
        rows[0].drop(columns=volatile).reset_index(drop=True),
        rows[1].drop(columns=volatile).reset_index(drop=True),
    )
    auction = rows[0][rows[0]["assignment.protocol"] == "sequential_auction"]
    assert (auction["tasks_completed"] > 0).all()


def _summary(folder: Path) -> dict[str, object]:
    return dict(json.loads((folder / "summary.json").read_text()))


def test_a_loss_model_of_labkits_loses_exactly_every_nth_message_of_a_link(plugins, tmp_path):
    done = cosim(plugins, "run", "warehouse-random", *SHORT, "--out", str(tmp_path / "run"),
                 "--set", "network.loss_model='every_nth'", "--set", "every_nth.n=4")  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert _summary(tmp_path / "run")["loss_rate_configured"] == 0.25
    messages = pd.read_parquet(tmp_path / "run" / "tables" / "messages.parquet")
    remote = messages[messages["src_host"] != messages["dst_host"]].sort_values("t_sent_ns")
    for (_src, _dst), copies in remote.groupby(["src_host", "dst_host"], observed=True):
        lost = (copies["status"] == "lost").to_numpy()
        assert lost.tolist() == [(k + 1) % 4 == 0 for k in range(len(lost))]


def test_a_network_backend_of_labkits_replaces_the_links_model(plugins, tmp_path):
    done = cosim(plugins, "run", "warehouse-random", *SHORT, "--out", str(tmp_path / "run"),
                 "--set", "network.backend='wired'", "--set", "wired.max_ms=2.0")  # fmt: skip
    assert done.returncode == 0, done.stderr
    summary = _summary(tmp_path / "run")
    messages = pd.read_parquet(tmp_path / "run" / "tables" / "messages.parquet")
    remote = messages[messages["src_host"] != messages["dst_host"]]
    assert summary["wired_copies"] == len(remote) > 0 and set(remote["status"]) == {"delivered"}
    delay = remote["t_recv_ns"] - remote["t_sent_ns"]
    assert delay.min() >= 200_000 and delay.max() <= 2_000_000
    assert "link_changes" not in summary  # the links backend did not run
    refused = cosim(plugins, "check", "warehouse-random", "--set", "network.backend='wired'",
                    "--set", "network.latency_ms=5.0")  # fmt: skip
    assert refused.returncode == 2
    assert "latency_ms = 5.0: expected 0 with backend 'wired' (only 'links' read" in refused.stderr


def test_a_pose_source_of_labkits_tracks_every_robot_at_its_rate(plugins, tmp_path):
    done = cosim(plugins, "run", "warehouse-random", *SHORT, "--out", str(tmp_path / "run"),
                 "--set", "mocap.source='gnss'", "--set", "gnss.rate_hz=5.0")  # fmt: skip
    assert done.returncode == 0, done.stderr
    summary = _summary(tmp_path / "run")
    assert summary["gnss_fixes"] == 4 * 5 * 30  # 4 robots at 5 Hz for 30 s
    # every fix went through the pose intake: accepted, or refused as a jump (2 cm noise on
    # a robot at full speed may pass the jump tolerance)
    taken = summary["mocap_poses"] + summary["mocap_rejected_jumps"]
    assert taken == summary["gnss_fixes"] and summary["mocap_poses"] >= 0.95 * taken


LABKITS = [
    "sequential_auction", "pure_pursuit", "rangefinder", "every_nth", "wired", "gnss",
    "sections:sequential_auction", "sections:pure_pursuit", "sections:rangefinder",
    "sections:every_nth", "sections:wired", "sections:gnss",
]  # fmt: skip


@pytest.mark.parametrize("name", LABKITS)
def test_cosim_check_plugin_passes_on_every_plugin_of_labkit(plugins, name):
    done = cosim(plugins, "check-plugin", name)
    assert done.returncode == 0, done.stdout + done.stderr
    first, *checks, last = done.stdout.splitlines()
    assert first.startswith("checking ") and first.endswith(", labkit 0.1.0)")
    assert all(line.startswith("ok   ") for line in checks), done.stdout
    assert "checks passed" in last and "skipped" not in last

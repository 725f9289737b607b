import json
import re
import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest

from cosim.cli.main import main
from tests.conftest import REPO, cosim_main

REPO_ROOT = REPO

SMALL = [
    "--set",
    "world.size_m=[12.0, 12.0]",
    "--set",
    "world.shelf_count=4",
    "--set",
    "robots.count=3",
    "--set",
    "lidar.beams=90",
]


def cosim_process(*args: str, cwd: Path | None = None) -> subprocess.CompletedProcess[str]:
    """``python -m cosim ARGS`` in its own process."""
    return subprocess.run(
        [sys.executable, "-m", "cosim", *args], capture_output=True, text=True, cwd=cwd, timeout=120
    )


cosim_cli = cosim_main


@pytest.mark.slow
def test_run_writes_the_contracted_folder_and_says_where(tmp_path):
    out = tmp_path / "run"
    done = cosim_process("run", "warehouse-random", "--out", str(out), "--duration-s", "2", *SMALL)
    assert done.returncode == 0, done.stderr
    assert f"results: {out}/" in done.stdout
    assert "real time" in done.stdout
    summary = json.loads((out / "summary.json").read_text())
    for key in (
        "scenario",
        "seed",
        "version",
        "sim_time_s",
        "wall_time_s",
        "real_time_factor",
        "robots",
        "events",
    ):
        assert key in summary
    assert summary["sim_time_s"] == 2.0
    assert summary["robots"] == 3
    assert (out / "scenario.toml").read_text().startswith("# resolved from preset warehouse-random")
    poses = pd.read_parquet(out / "tables" / "poses.parquet")
    assert list(poses.columns) == ["t_s", "robot", "x_m", "y_m", "yaw_rad", "v_mps", "w_radps"]
    messages = pd.read_parquet(out / "tables" / "messages.parquet")
    assert list(messages.columns[:7]) == [
        "t_sent_s",
        "t_recv_s",
        "src_host",
        "dst_host",
        "topic",
        "bytes",
        "status",
    ]
    events = pd.read_parquet(out / "tables" / "events.parquet")
    assert list(events.columns[:4]) == ["t_s", "source", "kind", "detail"]


def test_the_resolved_scenario_reproduces_the_run(tmp_path):
    first, second = tmp_path / "a", tmp_path / "b"
    assert (
        cosim_cli(
            "run",
            "warehouse-random",
            "--out",
            str(first),
            "--seed",
            "5",
            "--duration-s",
            "1.5",
            "--quiet",
            *SMALL,
        ).returncode
        == 0
    )
    assert (
        cosim_cli("run", str(first / "scenario.toml"), "--out", str(second), "--quiet").returncode
        == 0
    )
    for table in ("poses", "messages", "events"):
        pd.testing.assert_frame_equal(
            pd.read_parquet(first / "tables" / f"{table}.parquet"),
            pd.read_parquet(second / "tables" / f"{table}.parquet"),
        )


def test_run_refuses_a_non_empty_output_folder_unless_forced_and_a_run_folder(tmp_path):
    out = tmp_path / "run"
    out.mkdir()
    (out / "notes.txt").write_text("keep me")
    refused = cosim_cli("run", "warehouse-random", "--out", str(out), "--duration-s", "0.5", *SMALL)
    assert refused.returncode == 2
    assert "not empty" in refused.stderr and "--force" in refused.stderr
    args = ("run", "warehouse-random", "--out", str(out), "--duration-s", "0.5", "--force")
    mine = cosim_cli(*args, *SMALL)
    assert mine.returncode == 2 and mine.stderr.count("\n") == 1
    assert f"{out}: not a run folder (no .cosim-run" in mine.stderr
    (out / "notes.txt").rename(tmp_path / "notes.txt")
    assert cosim_cli(*args, "--quiet", *SMALL).returncode == 0  # a run folder now
    (tmp_path / "notes.txt").rename(out / "notes.txt")
    forced = cosim_cli(
        "run",
        "warehouse-random",
        "--out",
        str(out),
        "--duration-s",
        "0.5",
        "--force",
        "--quiet",
        *SMALL,
    )
    assert forced.returncode == 0, forced.stderr
    assert forced.stdout == ""
    assert (out / "notes.txt").read_text() == "keep me"
    assert (out / "summary.json").exists()


@pytest.mark.parametrize(
    ("content", "fragment"),
    [
        ("[lidar]\nrate_hzz = 10\n", "unknown key 'rate_hzz'; did you mean 'rate_hz'?"),
        ('[robots]\ncount = "4"\n', "[robots] count = '4': expected an integer > 0"),
        ("[lidar]\nrate_hz = -1\n", "[lidar] rate_hz = -1: expected a number >= 0.001"),
        ("[robots]\ncount = 0\n", "[robots] count = 0: expected an integer > 0"),
        ("[robots\ncount = 0\n", "malformed TOML"),
    ],
)
def test_invalid_scenario_files_exit_2_with_one_line_naming_the_key(tmp_path, content, fragment):
    path = tmp_path / "bad.toml"
    path.write_text(content)
    done = cosim_cli("run", str(path), "--out", str(tmp_path / "out"))
    assert done.returncode == 2
    assert done.stderr.count("\n") == 1, done.stderr
    assert str(path) in done.stderr
    assert fragment in done.stderr
    assert "Traceback" not in done.stderr
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize(
    ("args", "fragment"),
    [
        (["check", "missing.toml"], "missing.toml: scenario file not found"),
        (["check", "warehouse-randomm"], "did you mean 'warehouse-random'"),
        (
            ["check", "warehouse-random", "--set", "lidar.beams=-3"],
            "--set lidar.beams: [lidar] beams = -3: expected an integer >= 0",
        ),
        (["check", "warehouse-random", "--set", "nonsense"], "expected section.key=value"),
        (["run", "warehouse-random", "--seed", "-1"], "expected an integer >= 0"),
        (["run", "warehouse-random", "--duration-s", "0"], "0 is not a duration >= 1e-06"),
        (["run", "warehouse-random", "--set", "world.shelf_count=400"], "world.shelf_count = 400"),
        (
            ["check", "warehouse-random", "--set", "world.shelf_count=400"],
            "world.shelf_count = 400",
        ),
        (["frobnicate"], "invalid choice"),
        (["run", "warehouse-random", "--bag", "rosbag1"], "argument --bag: invalid choice"),
        (
            ["run", "warehouse-random", "--set", 'record.topics=["/robot_*/lidar"]'],
            "pattern '/robot_*/lidar' matches no topic of this run",
        ),
        (
            ["check", "warehouse-random", "--set", 'record.topics=["/nothing"]'],
            "pattern '/nothing' matches no topic",
        ),
        (["run", "warehouse-random", "--live-port", "70000"], "not a TCP port"),
        (["run", "warehouse-random", "--live-rate", "0"], "not a finite number > 0"),
        (["run", "warehouse-random", "--threads", "0"], "argument --threads: 0 is not an"),
        (["run", "warehouse-random", "--threads", "65"], "65 is more than 64 threads"),
        (["run", "warehouse-random", "--threads", "two"], "'two' is not an integer"),
        (["bag", "info", "."], "not a ROS 2 bag"),
        (["bag", "info", "nowhere"], "nowhere: no such file or folder"),
        (["bag"], "the following arguments are required"),
        (["plot", "."], "scenario.toml"),
        (["plot", ".", "--at", "ten"], "'ten' in 'ten' is not a number"),
    ],
)
def test_invalid_command_lines_exit_2_with_one_line(tmp_path, args, fragment):
    done = cosim_cli(*args, cwd=tmp_path)
    assert done.returncode == 2
    assert fragment in done.stderr
    assert done.stderr.count("\n") == 1, done.stderr


def test_check_validates_without_running(capsys):
    assert main(["check", "warehouse-random", "--set", "robots.count=6"]) == 0
    out = capsys.readouterr().out
    assert out.startswith("ok: warehouse-random (preset warehouse-random): 6 robots")


def test_check_can_print_the_resolved_scenario(capsys):
    assert main(["check", "warehouse-random", "--print"]) == 0
    assert "[lidar]\nbeams = 360" in capsys.readouterr().out


def test_check_print_writes_the_scenario_alone_to_stdout_and_the_printed_file_runs(tmp_path):
    printed = cosim_main("check", "warehouse-random", "--print")
    assert printed.returncode == 0, printed.stderr
    assert printed.stderr.startswith("ok: warehouse-random (preset warehouse-random)")
    assert "ok:" not in printed.stdout
    (tmp_path / "my-hall.toml").write_text(printed.stdout)  # `... --print > my-hall.toml`
    ran = cosim_main(
        "run", "my-hall.toml", "--out", "runs/mine", "--duration-s", "2", "--bag", "none",
        cwd=tmp_path,
    )  # fmt: skip
    assert ran.returncode == 0, ran.stderr
    assert json.loads((tmp_path / "runs" / "mine" / "summary.json").read_text())["robots"] == 4


def test_scenarios_lists_every_preset_on_one_line_each(capsys):
    assert main(["scenarios"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert any(line.startswith("warehouse-random ") for line in lines)
    assert all(len(line.split()) > 1 for line in lines)


@pytest.mark.slow
def test_help_explains_every_command():
    done = cosim_process("--help")
    assert done.returncode == 0
    for command in ("run", "check", "scenarios"):
        assert command in done.stdout
    run_help = cosim_cli("run", "--help").stdout
    for flag in ("--out", "--seed", "--duration-s", "--set", "--quiet", "--force", "--bag"):
        assert flag in run_help
    for flag in ("--figures", "--gif", "--live", "--live-port", "--live-rate", "--live-host"):
        assert flag in run_help
    assert "RUN_DIR" in cosim_cli("plot", "--help").stdout
    assert "BAG" in cosim_cli("bag", "info", "--help").stdout


@pytest.mark.slow
def test_run_with_figures_writes_them_and_says_where(tmp_path):
    out = tmp_path / "run"
    done = cosim_cli(
        "run", "warehouse-random", "--out", str(out), "--duration-s", "2", "--figures", *SMALL
    )
    assert done.returncode == 0, done.stderr
    assert (out / "figures" / "trajectories.png").is_file()
    assert "figures: " in done.stdout and f"bag: {out}/bag/" in done.stdout
    again = cosim_cli("plot", str(out), "--at", "0.5,1.5")
    assert again.returncode == 0, again.stderr
    assert f"wrote {out}/figures/snapshots.png" in again.stdout


def test_world_writes_a_picture_a_map_and_an_sdf_world(tmp_path):
    done = cosim_cli(
        "world",
        "warehouse-rows",
        "--png",
        str(tmp_path / "w.png"),
        "--map",
        str(tmp_path / "w.yaml"),
        "--sdf",
        str(tmp_path / "w.sdf"),
    )
    assert done.returncode == 0, done.stderr
    for name in ("w.png", "w.yaml", "w.pgm", "w.sdf"):
        assert (tmp_path / name).stat().st_size > 0
    assert f"wrote {tmp_path / 'w.sdf'}" in done.stdout


def test_world_without_outputs_describes_the_world(capsys):
    assert main(["world", "fleet50"]) == 0
    out = capsys.readouterr().out
    assert "fleet50" in out and "72 shelves" in out and "50 robots" in out


def test_wander_without_a_lidar_is_refused_naming_the_keys(tmp_path):
    done = cosim_cli(
        "check", "warehouse-random", "--set", "robots.driver=wander", "--set", "lidar.beams=0"
    )
    assert done.returncode == 2
    done = cosim_cli(
        "run",
        "warehouse-random",
        "--set",
        "robots.driver=wander",
        "--set",
        "lidar.beams=0",
        "--out",
        str(tmp_path / "o"),
    )
    assert done.returncode == 2
    assert "driver = 'wander': expected lidar.beams > 0" in done.stderr


@pytest.mark.parametrize(
    ("setting", "fragment"),
    [
        ("network.latency_ms=-5", "[network] latency_ms = -5: expected a number >= 0"),
        ("network.loss_prob=1.5", "[network] loss_prob = 1.5: expected a number >= 0 and <= 1"),
        ("network.ge_p=-0.1", "[network] ge_p = -0.1: expected a number >= 0 and <= 1"),
        ("network.profile=wifi_bad", "profile = 'wifi_bad': expected one of 'ideal'"),
        ("network.topology=star", "topology = 'star': expected a registered network topology"),
        ("network.loss_prob=0.2", "loss_prob = 0.2: expected 0 with loss_model 'none'"),
        (
            'network.partitions=[{from_s=1.0, to_s=2.0, hosts=["robot_42"]}]',
            "names host 'robot_42'",
        ),
        (
            'network.partitions=[{from_s=2.0, to_s=1.0, hosts=["base"]}]',
            "[network.partitions[0]] to_s = 1.0: expected a time after from_s",
        ),
    ],
)
def test_invalid_network_settings_exit_2_naming_the_key(tmp_path, setting, fragment):
    done = cosim_cli("check", "warehouse-random", "--set", setting, cwd=tmp_path)
    assert done.returncode == 2, done.stdout
    assert fragment in done.stderr
    assert done.stderr.count("\n") == 1, done.stderr


@pytest.mark.parametrize(
    ("content", "fragment"),
    [
        ("", "latency_csv"),
        ("delay_ms\n1.0\nabc\n", "line 3"),
        ("delay_ms\n1.0\n-2.0\n", "line 3"),
    ],
)
def test_an_empty_or_malformed_delay_csv_exits_2_naming_the_file(tmp_path, content, fragment):
    (tmp_path / "delays.csv").write_text(content)
    scenario = tmp_path / "s.toml"
    scenario.write_text('[network]\nlatency_model = "empirical"\nlatency_csv = "delays.csv"\n')
    done = cosim_cli("check", str(scenario))
    assert done.returncode == 2, done.stdout
    assert "latency_csv" in done.stderr and "delays.csv" in done.stderr
    assert fragment in done.stderr
    assert done.stderr.count("\n") == 1, done.stderr


def test_a_delay_csv_next_to_the_scenario_is_found_and_used(tmp_path):
    (tmp_path / "delays.csv").write_text("delay_ms\n4.0\n4.0\n6.0\n")
    scenario = tmp_path / "s.toml"
    scenario.write_text('[network]\nlatency_model = "empirical"\nlatency_csv = "delays.csv"\n')
    done = cosim_cli("check", str(scenario), "--print", cwd=REPO_ROOT)
    assert done.returncode == 0, done.stderr
    assert f'latency_csv = "{tmp_path / "delays.csv"}"' in done.stdout


def test_a_standin_with_a_negative_rate_is_one_line_and_exit_2(capsys):
    assert main(["standin", "--name", "robot_1", "--rate-hz", "-1"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "rate_hz = -1.0" in err[0]


def test_a_standin_on_a_domain_dds_cannot_have_is_one_line_and_exit_2(capsys):
    assert main(["standin", "--name", "robot_1", "--domain", "300", "--duration-s", "1"]) == 2
    assert "300" in capsys.readouterr().err


def test_run_standin_without_a_physical_robot_is_refused(capsys, tmp_path):
    assert main(["run", "lab-room", "--standin", "--out", str(tmp_path / "r"), "--quiet"]) == 2
    assert "no physical robot" in capsys.readouterr().err
    assert not (tmp_path / "r").exists()


@pytest.mark.parametrize("preset", ["lab-real-in-virtual", "lab-mixed"])
def test_the_mixed_reality_presets_check_without_touching_the_network(preset, capsys):
    assert main(["check", preset]) == 0


def test_the_run_summary_leads_with_tasks_and_rounds_to_meaningful_digits(tmp_path, capsys):
    out = tmp_path / "run"
    assert main(["run", "warehouse-random", *SMALL, "--duration-s", "20", "--bag", "none",
                 "--out", str(out)]) == 0  # fmt: skip
    first, second = capsys.readouterr().out.splitlines()[:2]
    assert re.fullmatch(
        r"warehouse-random seed 1: 20 s simulated in \d+\.\d\d s \([\d.]+x real time\), "
        r"(plus [\d.]+ s compiling kernels on this first run \(cached now\), )?"
        r"3 robots, [\d,]+ events, [\d,]+ messages",
        first,
    )
    assert re.match(r"  \d+ tasks? completed \([\d.]+ per min, [\d.]+ s mean latency\)", second)
    assert "goals reached" not in second
    clearance = re.search(r"(-?[\d.]+) m smallest clearance", second).group(1)
    assert len(clearance.split(".")[1]) == 2


def test_the_fleet_managers_preset_with_mapping_exits_2_naming_both_ways_out(tmp_path):
    done = cosim_cli(
        "run", "fleet50", "--set", "mapping.enabled=true", "--out", str(tmp_path / "out")
    )
    assert done.returncode == 2
    assert done.stderr.count("\n") == 1, done.stderr
    assert "[navigation] traffic = 'pibt' with [mapping] enabled = true" in done.stderr
    assert "navigation.traffic = 'none'" in done.stderr
    assert "Traceback" not in done.stderr
    assert not (tmp_path / "out").exists()

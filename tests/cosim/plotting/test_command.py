import shutil
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest
from PIL import Image

import cosim
from cosim.core.errors import ConfigError, ExportError
from cosim.plotting.command import plot_run, snapshot_times
from cosim.plotting.rundata import load_run
from tests.conftest import REPO, SMALL, cosim_main
from tests.cosim.plotting.conftest import PNG_MAGIC
from tests.packages import on_path, write_package

EVERY_FIGURE = ["trajectories.png", "snapshots.png", "tasks.png", "network.png", "assignment.png"]
MAX_PNG_BYTES = 2_000_000
MAX_PNG_SIDE_PX = 3_000


def _assert_bounded_pngs(paths: list[Path]) -> None:
    for path in paths:
        assert path.read_bytes().startswith(PNG_MAGIC), path
        assert path.stat().st_size < MAX_PNG_BYTES, path
        with Image.open(path) as image:
            image.verify()
            assert max(image.size) < MAX_PNG_SIDE_PX, (path, image.size)


@pytest.mark.slow
def test_a_task_run_gets_every_figure_as_a_bounded_png_in_its_figures_folder(task_run, tmp_path):
    run_dir = Path(shutil.copytree(task_run, tmp_path / "run"))
    written = plot_run(run_dir)
    assert written == [run_dir / "figures" / name for name in EVERY_FIGURE]
    _assert_bounded_pngs(written)
    assert sorted(p.name for p in (run_dir / "figures").iterdir()) == sorted(EVERY_FIGURE)


def test_figures_go_to_out_when_it_is_given(waypoint_run, tmp_path):
    written = plot_run(waypoint_run, out=tmp_path / "elsewhere")
    assert {p.parent for p in written} == {tmp_path / "elsewhere"}
    assert not (waypoint_run / "figures").exists()


def test_figures_whose_data_the_run_lacks_are_skipped_not_drawn_empty(waypoint_run, tmp_path):
    written = plot_run(waypoint_run, out=tmp_path / "figures")
    assert [p.name for p in written] == ["trajectories.png", "snapshots.png"]
    assert sorted(p.name for p in (tmp_path / "figures").iterdir()) == [
        "snapshots.png",
        "trajectories.png",
    ]


@pytest.mark.slow
def test_an_old_style_run_folder_without_any_newer_table_still_plots(task_run, copy_of, tmp_path):
    run_dir = copy_of(task_run)
    tables = run_dir / "tables"
    for newer in ("tasks", "assignments", "navigation"):
        (tables / f"{newer}.parquet").unlink()
    messages = pd.read_parquet(tables / "messages.parquet")
    messages.drop(columns=["t_sent_ns", "t_recv_ns"]).to_parquet(tables / "messages.parquet")
    written = plot_run(run_dir, out=tmp_path / "figures")
    assert [p.name for p in written] == ["trajectories.png", "snapshots.png", "network.png"]
    _assert_bounded_pngs(written)


@pytest.mark.slow
def test_a_fleet_too_large_for_a_legend_entry_per_robot_plots_bounded_figures(tmp_path):
    overrides = {**SMALL, "robots.count": 12, "world.size_m": [16.0, 16.0]}
    cosim.run(cosim.load_scenario("warehouse-random", overrides=overrides), out=tmp_path / "r")
    _assert_bounded_pngs(plot_run(tmp_path / "r"))


@pytest.mark.slow
def test_the_gif_is_written_with_the_figures_and_listed_last(waypoint_run, tmp_path):
    written = plot_run(waypoint_run, gif=True, out=tmp_path / "figures")
    assert written[-1] == tmp_path / "figures" / "run.gif"
    assert written[-1].read_bytes()[:6] == b"GIF89a"


def test_snapshot_times_default_to_four_evenly_spaced_times_within_the_run(task_run):
    run = load_run(task_run)
    assert snapshot_times(run, None) == [5.0, 10.0, 15.0, float(run.track.t_s[-1])]
    assert snapshot_times(run, [0, 7.5]) == [0.0, 7.5]


def test_the_default_snapshots_of_the_paper_scenario_3_include_t_25_s() -> None:
    scenario = cosim.load_scenario("lab-mixed")
    run = SimpleNamespace(
        scenario=scenario, track=SimpleNamespace(t_s=np.arange(0.0, 59.95, 0.1)), path=Path(".")
    )
    times = snapshot_times(run, None)  # type: ignore[arg-type]
    assert 25.0 in times
    assert times == sorted(times) and max(times) <= 59.9 + 1e-9


@pytest.mark.parametrize("at", [[99.0], [-1.0], [float("nan")], ["soon"]])
def test_a_snapshot_time_outside_the_run_is_refused_naming_the_value(task_run, tmp_path, at):
    with pytest.raises(ExportError, match=rf"snapshot time {at[0]!r}.*within the run, 0 to 20 s"):
        plot_run(task_run, at=at, out=tmp_path / "figures")
    assert not (tmp_path / "figures").exists()


def test_no_snapshot_time_or_too_many_are_refused(task_run, tmp_path):
    for at in ([], [1.0] * 13):
        with pytest.raises(ExportError, match=f"{len(at)} snapshot times: expected 1 to 12"):
            plot_run(task_run, at=at, out=tmp_path / "figures")


def _without_scenario(run_dir: Path) -> None:
    (run_dir / "scenario.toml").unlink()


def _without_tables(run_dir: Path) -> None:
    shutil.rmtree(run_dir / "tables")


def _garbage_poses(run_dir: Path) -> None:
    (run_dir / "tables" / "poses.parquet").write_bytes(b"not a parquet file")


def _poses_without_yaw(run_dir: Path) -> None:
    path = run_dir / "tables" / "poses.parquet"
    pd.read_parquet(path).drop(columns=["yaw_rad"]).to_parquet(path)


def _no_pose(run_dir: Path) -> None:
    path = run_dir / "tables" / "poses.parquet"
    pd.read_parquet(path).iloc[:0].to_parquet(path)


def _garbage_messages(run_dir: Path) -> None:
    (run_dir / "tables" / "messages.parquet").write_bytes(b"PAR1 broken")


@pytest.mark.parametrize(
    ("damage", "named", "expected"),
    [
        (_without_scenario, "", "no scenario.toml; expected a run folder"),
        (_without_tables, "tables/poses.parquet", "no such file; expected the poses table"),
        (_garbage_poses, "tables/poses.parquet", "cannot read as a parquet table"),
        (_poses_without_yaw, "tables/poses.parquet", "no column yaw_rad; expected"),
        (_no_pose, "tables/poses.parquet", "no pose; expected"),
        (_garbage_messages, "tables/messages.parquet", "cannot read as a parquet table"),
    ],
    ids=lambda v: getattr(v, "__name__", "")[1:] if callable(v) else None,
)
def test_a_damaged_run_folder_raises_one_line_naming_the_path(
    task_run, copy_of, tmp_path, damage, named, expected
):
    run_dir = copy_of(task_run)
    damage(run_dir)
    with pytest.raises(ExportError) as raised:
        plot_run(run_dir, out=tmp_path / "figures")
    message = str(raised.value)
    assert message.startswith(str(run_dir / named).rstrip("/"))
    assert expected in message
    assert "\n" not in message


def test_a_folder_that_does_not_exist_is_refused_naming_it(tmp_path):
    with pytest.raises(ExportError, match=rf"{tmp_path / 'nowhere'}: no such folder"):
        plot_run(tmp_path / "nowhere")


def test_an_invalid_scenario_toml_is_a_config_error_naming_the_file(task_run, copy_of):
    run_dir = copy_of(task_run)
    (run_dir / "scenario.toml").write_text("[robots]\ncount = 'many'\n")
    with pytest.raises(ConfigError, match=r"scenario\.toml"):
        plot_run(run_dir)


def test_an_unwritable_out_folder_is_an_export_error_naming_it(task_run, tmp_path):
    blocker = tmp_path / "blocker"
    blocker.write_text("a file where the folder should be")
    with pytest.raises(ExportError, match="blocker"):
        plot_run(task_run, out=blocker / "figures")


# --- runs of earlier formats, and of plugins no longer installed --------------------------------

OLD_RUNS = REPO / "tests" / "oldruns"
"""Run folders written by older cosim (tests/oldruns/README.md says how)."""


@pytest.mark.parametrize(
    ("folder", "notes"),
    [
        ("at-99e8d54", ""),
        (
            "before-462a048",
            "note: {scenario}: [humans] yield_s = 10.0 read as humans.avoid_robots = true "
            "(renamed in 462a048: people keep clear of robots through a speed model instead of "
            "stopping for one at most yield_s s; yield_s = 0 (never stopping) is avoid_robots = "
            "false)\n",
        ),
    ],
)
def test_a_run_folder_of_an_earlier_format_is_drawn_saying_how_it_was_read(folder, notes, tmp_path):
    run = OLD_RUNS / folder
    done = cosim_main("plot", str(run), "--out", str(tmp_path / "figures"))
    assert done.returncode == 0, done.stderr
    assert done.stderr == notes.format(scenario=run / "scenario.toml")
    assert sorted(p.name for p in (tmp_path / "figures").iterdir()) == sorted(EVERY_FIGURE)
    _assert_bounded_pngs(list((tmp_path / "figures").iterdir()))


ODOKIT = '''"""A lab's odometer: its own settings section, its own table."""

from dataclasses import dataclass

from cosim.core.hosts import HostId
from cosim.scenario.fields import param


@dataclass(frozen=True)
class OdometerSettings:
    """``[odometer]``: counting robot_1's odometry."""

    every: int = param(1, "count every n-th message", ge=1)


class Odometer:
    name = "odometer"
    requires = ("fleet",)

    def __init__(self, run):
        self.every = run.scenario.section(OdometerSettings).every
        self.count = 0
        self.table = run.recorder.table("odometer", ("t_s", "count"))

    def start(self, run):
        def on_odom(message, envelope):
            self.count += 1
            if self.count % self.every == 0:
                self.table.append(t_s=run.kernel.now_ns / 1e9, count=self.count)

        run.bus.subscribe("/robot_1/odom", HostId("robot_1"), on_odom)

    def finish(self, run):
        return {"odometer_messages": self.count}
'''


@pytest.mark.slow  # a short run with the plugin, then the same folder read without it
def test_a_run_made_with_a_plugin_since_uninstalled_is_drawn_and_refused_as_a_scenario(tmp_path):
    entry_points = {
        "cosim.adapters": {"odometer": "odokit.odometer:Odometer"},
        "cosim.sections": {"odometer": "odokit.odometer:OdometerSettings"},
    }
    site = write_package(
        tmp_path / "site", "odokit", "0.2.0", entry_points, {"odokit/odometer.py": ODOKIT}
    )
    run = tmp_path / "run"
    with on_path(site):
        scenario = cosim.load_scenario(
            "warehouse-random",
            {**SMALL, "scenario.adapters": ["odometer"], "odometer.every": 2},
        )
        cosim.run(scenario, duration_s=1.0, out=run)
    assert len(pd.read_parquet(run / "tables" / "odometer.parquet")) == 10
    done = cosim_main("plot", str(run), "--out", str(tmp_path / "figures"))
    assert done.returncode == 0, done.stderr
    assert done.stderr == (
        f"note: {run / 'scenario.toml'}: [odometer], scenario.adapters = ['odometer'] carried "
        "unread: no installed package provides them (the run used odokit 0.2.0); the run's "
        "tables are read without it\n"
    )
    assert (tmp_path / "figures" / "trajectories.png").is_file()
    again = cosim_main("run", str(run / "scenario.toml"), "--out", str(tmp_path / "again"))
    assert again.returncode == 2 and again.stderr.count("\n") == 1, again.stderr
    assert again.stderr == (
        f"cosim: error: {run / 'scenario.toml'}: unknown section [odometer]: no installed "
        "package registers it; the file was resolved with odokit 0.2.0, not installed here: "
        "install it to run this scenario (`cosim plot` and studies' reports read a run's "
        "tables without it)\n"
    )
    assert not (tmp_path / "again").exists()

"""SUMO's people in a run: seen by lidars, avoided by navigation, repeated exactly by seed."""

import math
import re
import subprocess
import sys
import threading
from collections.abc import Mapping
from typing import Any, ClassVar

import numpy as np
import pandas as pd
import pytest

import cosim
from adapters.humans.crowd import People
from adapters.humans.files import sumo_tool
from adapters.naming import topic
from adapters.world.warehouse import scenario_warehouse
from cosim.cli.main import main
from cosim.core.adapter import RunContext
from cosim.core.messages import LaserScan, Message
from cosim.core.registry import AdapterRegistry
from cosim.runner.execute import execute, run
from models.fleet.kinematics import FleetState
from models.world.warehouse import box_distance

pytestmark = pytest.mark.slow


class ScanTap:
    """Keeps every scan of robot_1 with the people as SUMO placed them at that instant."""

    name: ClassVar[str] = "scan_tap"
    requires: ClassVar[tuple[str, ...]] = ("lidar", "humans")
    seen: ClassVar[list[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]]] = []

    def __init__(self, run: RunContext) -> None:
        self.people = run.service(People)
        self.fleet = run.service(FleetState)
        ScanTap.seen = []

    def start(self, run: RunContext) -> None:
        def on_scan(message: Message, _envelope: Any) -> None:
            assert isinstance(message, LaserScan)
            pose = np.array([self.fleet.x[0], self.fleet.y[0], self.fleet.yaw[0]])
            people = np.column_stack([self.people.x_m, self.people.y_m])
            ScanTap.seen.append((pose, message.ranges_m.copy(), people, message.angle_min_rad))

        run.bus.subscribe(topic("robot_1", "scan"), cosim.core.hosts.HostId("robot_1"), on_scan)

    def finish(self, run: RunContext) -> Mapping[str, Any]:
        return {}


def test_people_appear_in_a_robots_scan_where_sumo_says_they_are():
    scenario = cosim.load_scenario(
        "warehouse-humans",
        {
            "world.size_m": [14.0, 10.0],
            "world.layout": "random",
            "world.shelf_count": 0,
            "robots.count": 1,
            "robots.placement": "explicit",
            "robots.positions": [[7.0, 5.0, 0.0]],
            "lidar.noise_std_m": 0.0,
            "lidar.dropout_prob": 0.0,
            "humans.workers": 6,
            "humans.standing": [[10.0, 5.0], [7.0, 8.0]],
            "scenario.duration_s": 20.0,
        },
    )
    registry = AdapterRegistry.from_entry_points().with_adapter(ScanTap)
    names = ["world", "fleet", "network", "collisions", "lidar", "humans", "poses", "scan_tap"]
    execute(scenario, names=names, registry=registry)
    radius = scenario.humans.worker_radius_m
    checked = 0
    robot_radius = scenario.robots.radius_m
    for pose, ranges, people, angle_min in ScanTap.seen:
        centre = np.hypot(people[:, 0] - pose[0], people[:, 1] - pose[1])
        if len(people) and centre.min() < robot_radius + radius:
            continue  # someone walked into the robot (at rest): the lidar sits inside them
        increment = 2 * math.pi / len(ranges)
        for x, y in people:
            distance = math.hypot(x - pose[0], y - pose[1])
            if not 1.0 < distance < scenario.lidar.range_max_m - 1:
                continue
            bearing = math.atan2(y - pose[1], x - pose[0]) - pose[2]
            beam = round(((bearing - angle_min) % (2 * math.pi)) / increment) % len(ranges)
            # the beam through the centre hits the near side of the disc, or someone in front
            assert ranges[beam] <= distance - radius + 0.02
            others = [
                math.hypot(px - pose[0], py - pose[1]) - radius
                for px, py in people
                if (px, py) != (x, y)
            ]
            if ranges[beam] < distance - radius - 0.02:
                assert min(others) <= ranges[beam] + 0.02  # hidden behind another person
            else:
                checked += 1
    assert checked > 100  # the standing pair alone gives two per scan


def _corridors(**extra):
    # a block in the middle: a lower and an upper corridor, 2.6 m wide each
    return cosim.load_scenario(
        "warehouse-humans",
        {
            "world.size_m": [14.0, 9.0],
            "world.layout": "random",
            "world.shelf_count": 0,
            "world.obstacles": [[4.0, 2.6, 10.0, 6.4]],
            "robots.count": 1,
            "robots.placement": "explicit",
            "robots.positions": [[1.5, 1.3, 0.0]],
            "robots.driver": "navigation",
            "navigation.goals": [[1.5, 1.3], [12.5, 1.3]],
            "humans.workers": 0,
            "scenario.duration_s": 40.0,
            "record.bag": "none",
            **extra,
        },
    )


def test_a_worker_standing_in_an_aisle_makes_the_robot_replan_or_wait_and_never_collide():
    result = run(_corridors(**{"humans.standing": [[7.0, 1.3]]}))
    summary = result.summary
    assert summary["humans_collisions"] == 0
    assert summary["collisions"] == 0
    assert summary["humans_min_distance_m"] > 0.0
    navigation = result.tables["navigation"]
    poses = result.tables["poses"]
    robot = poses[poses["robot"] == "robot_1"]
    replanned = (navigation["event"] == "replan").any()
    waited = summary["humans_robot_stops"] > 0
    assert replanned or waited
    # it never reached the person's spot without going round them
    beside = robot[(robot["x_m"] - 7.0).abs() < 0.3]
    assert ((beside["y_m"] - 1.3).abs() > 0.25 + 0.33).all()


def test_without_the_standing_worker_the_robot_takes_the_lower_corridor_straight():
    result = run(_corridors(**{"humans.standing": [[7.0, 8.0]]}))  # someone out of the way
    poses = result.tables["poses"]
    assert result.summary["arrivals"] >= 1
    assert (poses["y_m"] < 2.6).all()


def _small(**extra):
    return cosim.load_scenario(
        "warehouse-humans", {"scenario.duration_s": 20.0, "record.bag": "none", **extra}
    )


@pytest.mark.slow
def test_two_runs_with_one_seed_are_identical_and_another_seed_moves_people_elsewhere():
    a = run(_small())
    b = run(_small())
    for name, frame in a.deterministic_tables().items():
        pd.testing.assert_frame_equal(frame, b.deterministic_tables()[name], obj=name)
    # SUMO's files are the same but for the date netconvert writes into its header
    assert a.files.keys() == b.files.keys()
    for name in ("sumo/humans.rou.xml", "sumo/aisles.edg.xml", "sumo/humans.sumocfg"):
        assert a.files[name] == b.files[name]
    strip = re.compile(rb"<!--.*?-->", re.S)
    assert strip.sub(b"", a.files["sumo/aisles.net.xml"]) == strip.sub(
        b"", b.files["sumo/aisles.net.xml"]
    )
    humans = a.tables["humans"]
    assert set(humans["id"]) == {f"worker_{k}" for k in range(10)}
    summary = a.summary
    assert summary["humans_tasks_met_people"] <= summary["tasks_completed"]
    for key in ("humans_task_latency_met_people_s", "humans_task_latency_clear_s"):
        assert summary[key] is None or 0 < summary[key] <= 20.0
    c = run(_small(), seed=2)
    assert not c.tables["humans"][["x_m", "y_m"]].equals(humans[["x_m", "y_m"]])


def test_the_humans_table_has_its_contract_columns_and_people_stay_in_the_aisles():
    result = run(_small())
    humans = result.tables["humans"]
    assert list(humans.columns) == ["t_s", "id", "kind", "x_m", "y_m", "yaw_rad", "speed_mps"]
    assert set(humans["kind"]) == {"person"}
    assert humans["speed_mps"].between(0, 2.0).all()
    assert humans["x_m"].between(0, 30).all() and humans["y_m"].between(0, 30).all()
    # nobody reaches into a shelf or wall
    world = scenario_warehouse(result.scenario)
    gap = box_distance(humans[["x_m", "y_m"]].to_numpy(), world.boxes).min(axis=1)
    assert gap.min() >= result.scenario.humans.worker_radius_m - 1e-9
    assert humans["t_s"].min() == pytest.approx(0.1)  # SUMO's first step
    per_step = humans.groupby("t_s").size()
    assert per_step.max() <= 10
    assert np.allclose(np.diff(per_step.index.to_numpy()), 0.1)


@pytest.mark.slow
def test_the_run_folder_holds_sumo_files_that_sumo_itself_loads(tmp_path):
    result = run(_small(), out=tmp_path / "run")
    folder = tmp_path / "run" / "sumo"
    assert {p.name for p in folder.iterdir()} >= {
        "aisles.net.xml",
        "humans.rou.xml",
        "humans.sumocfg",
        "aisles.nod.xml",
        "aisles.edg.xml",
    }
    done = subprocess.run(
        [str(sumo_tool("sumo")), "-c", str(folder / "humans.sumocfg"), "--end", "5"],
        capture_output=True,
        text=True,
        timeout=60,
        check=False,
    )
    assert done.returncode == 0, done.stderr
    assert (tmp_path / "run" / "tables" / "humans.parquet").is_file()
    assert result.summary["humans_sumo_steps"] == 199  # 0.1 s ... 19.9 s (the run ends at 20 s)


@pytest.mark.slow
def test_two_runs_at_once_in_one_process_both_work_and_agree():
    results: dict[int, Any] = {}

    def go(key: int) -> None:
        results[key] = run(_small(**{"scenario.duration_s": 8.0}))

    threads = [threading.Thread(target=go, args=(k,)) for k in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert sorted(r.summary["humans_sumo_in_process"] for r in results.values()) == [False, True]
    pd.testing.assert_frame_equal(results[0].tables["humans"], results[1].tables["humans"])


@pytest.mark.slow
def test_forklifts_drive_and_are_seen_as_two_discs_each():
    result = run(_small(**{"humans.workers": 2, "humans.forklifts": 2}))
    humans = result.tables["humans"]
    forklifts = humans[humans["kind"] == "forklift"]
    assert set(forklifts["id"]) == {"forklift_0", "forklift_1"}
    assert forklifts["speed_mps"].max() > 0.5
    assert result.summary["humans_forklifts"] == 2


def test_a_room_too_narrow_for_people_is_one_line_and_exit_status_2(capsys):
    status = main(
        ["run", "lab-mixed", "--set", "humans.workers=2", "--set", "humans.worker_radius_m=1.0",
         "--duration-s", "1", "--bag", "none"]
    )  # fmt: skip
    err = capsys.readouterr().err
    assert status == 2
    assert "humans.worker_radius_m = 1.0:" in err and "Traceback" not in err
    assert len(err.strip().splitlines()) == 1


@pytest.mark.slow
def test_a_missing_libsumo_is_one_line_naming_it_and_exit_status_2():
    code = (
        "import sys; sys.modules['libsumo'] = None\n"
        "from cosim.cli.main import main\n"
        "sys.exit(main(['run', 'warehouse-humans', '--duration-s', '1', '--bag', 'none']))\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=120, check=False
    )
    assert done.returncode == 2
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and "libsumo" in lines[0] and "humans" in lines[0]

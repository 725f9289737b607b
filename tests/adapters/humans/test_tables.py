from dataclasses import replace

import numpy as np
import pytest

import cosim
from adapters.humans.crowd import People
from adapters.humans.settings import HumansConfig
from adapters.humans.tables import HUMAN_COLUMNS, HUMANS, PEOPLE_KINDS, HumanRecords
from adapters.tasks.source import TaskSourceAdapter
from cosim.core.adapter import RunContext
from cosim.core.timebase import s_to_ns
from cosim.recording.dataframes import table_frame
from cosim.runner.assembly import assemble
from models.fleet.kinematics import FleetState
from models.tasks.book import Task, TaskStatus
from tests.conftest import SMALL

UNITS = {"_s": "(s)", "_m": "(m)", "_rad": "(rad)", "_mps": "(m/s)"}


def test_the_humans_table_has_the_documented_columns_with_units_in_map():
    assert HUMANS.name == "humans"
    assert HUMAN_COLUMNS == ("t_s", "id", "kind", "x_m", "y_m", "yaw_rad", "speed_mps")
    for column, meaning in HUMANS.columns.items():
        for suffix, unit in UNITS.items():
            if column.endswith(suffix):
                assert meaning.endswith(unit), column
    for column in ("x_m", "y_m", "yaw_rad"):
        assert "in map" in HUMANS.columns[column]


def test_its_categorical_columns_are_columns_of_it_and_kinds_are_documented():
    assert set(HUMANS.categorical) == {"id", "kind"} <= set(HUMANS.columns)
    assert set(HUMANS.volatile) <= set(HUMANS.columns)
    assert PEOPLE_KINDS == ("person", "forklift")
    assert all(kind in HUMANS.columns["kind"] for kind in PEOPLE_KINDS)


APART = {
    "robots.placement": "explicit",
    "robots.positions": [[2.0, 1.0, 0.0], [6.0, 1.0, 0.0], [10.0, 1.0, 0.0]],
}
"""Three robots 4 m apart: a person near one is far from the others."""


def fleet_run(**overrides: object) -> RunContext:
    scenario = cosim.load_scenario("warehouse-random", {**SMALL, **APART, **overrides})
    return assemble(scenario, names=["fleet", "collisions"]).run


def people_at(points: list[tuple[str, str, float, float]], radius_m: float = 0.25) -> People:
    people = People()
    people.names = [name for name, _, _, _ in points]
    people.kinds = [kind for _, kind, _, _ in points]
    people.x_m = np.array([x for _, _, x, _ in points])
    people.y_m = np.array([y for _, _, _, y in points])
    people.yaw_rad = np.zeros(len(points))
    people.speed_mps = np.full(len(points), 1.2)
    people.discs = np.array([[x, y, radius_m] for _, _, x, y in points]).reshape(-1, 3)
    people.disc_names = list(people.names)
    return people


def test_people_are_sampled_at_the_record_rate_whatever_the_step():
    run = fleet_run()
    records = HumanRecords(run, replace(HumansConfig(), record_hz=2.0))
    far = people_at([("w0", "person", 100.0, 100.0), ("f0", "forklift", 90.0, 100.0)])
    for k in range(11):  # SUMO steps of 0.1 s for 1 s
        records.sample(s_to_ns(0.1 * k), far)
    frame = table_frame(records.table)
    assert list(frame.t_s) == [0.0, 0.0, 0.5, 0.5, 1.0, 1.0]
    assert list(frame.id) == ["w0", "f0"] * 3
    assert list(frame.kind) == ["person", "forklift"] * 3
    assert list(frame.x_m) == [100.0, 90.0] * 3
    assert records.seen == {"w0", "f0"}


def test_an_empty_crowd_writes_no_rows():
    records = HumanRecords(fleet_run(), HumansConfig())
    records.sample(0, People())
    assert len(records.table) == 0 and records.seen == set()


def test_a_person_close_to_a_robot_is_one_near_miss_event_per_episode():
    run = fleet_run()
    fleet = run.service(FleetState)
    records = HumanRecords(run, HumansConfig())
    x, y, r = float(fleet.x[0]), float(fleet.y[0]), float(fleet.radius_m[0])
    near = people_at([("w0", "person", x + r + 0.25 + 0.3, y)])  # 0.3 m footprint to footprint
    for k in range(5):  # a worker standing beside the robot
        records.sample(s_to_ns(0.1 * k), near)
    records.sample(s_to_ns(0.5), people_at([("w0", "person", 100.0, 100.0)]))
    records.sample(s_to_ns(0.6), near)
    events = table_frame(run.recorder.events)
    misses = events[events.kind == "near_miss"]
    assert list(misses.source) == ["robot_1", "robot_1"]
    assert list(misses.detail) == ["w0 at 0.30 m", "w0 at 0.30 m"]
    assert records.met["robot_1"] == [0, s_to_ns(0.6)]
    summary = records.summary(run)
    assert summary["humans_near_misses"] == 2
    assert summary["humans_min_distance_m"] == pytest.approx(0.3)


def test_a_robot_halting_with_a_person_near_is_stopped_by_people():
    run = fleet_run()
    fleet = run.service(FleetState)
    records = HumanRecords(run, HumansConfig())
    x, y = float(fleet.x[1]), float(fleet.y[1])
    person = people_at([("w3", "person", x + 1.2, y)])
    fleet.v[1] = 0.5
    records.sample(0, person)
    fleet.v[1] = 0.0
    records.sample(s_to_ns(0.1), person)
    events = table_frame(run.recorder.events)
    stops = events[events.kind == "stopped_by_person"]
    assert list(stops.source) == ["robot_2"]
    assert stops.detail.iloc[0].startswith("w3 at ")
    assert records.robot_stops.tolist() == [0, 1, 0]
    assert records.summary(run)["humans_robot_stops"] == 1


def test_contacts_with_people_and_forklifts_are_counted_apart_from_others():
    run = fleet_run()
    records = HumanRecords(run, HumansConfig())
    collisions = run.recorder.tables["collisions"]
    for kind, speed in (("person", 0.4), ("forklift", 0.0), ("shelf", 0.5), ("person", 0.01)):
        collisions.append(
            t_s=1.0, robot="robot_1", other="x", kind=kind, depth_m=0.01, speed_mps=speed
        )
    summary = records.summary(run)
    assert summary["humans_collisions"] == 3
    assert summary["humans_collisions_robot_moving"] == 1  # 0.01 m/s is a robot at rest


def test_a_run_without_people_nearby_has_no_distance_and_no_task_latencies():
    run = fleet_run()
    summary = HumanRecords(run, HumansConfig()).summary(run)
    assert summary == {
        "humans_seen": 0,
        "humans_min_distance_m": None,
        "humans_near_misses": 0,
        "humans_robot_stops": 0,
        "humans_collisions": 0,
        "humans_collisions_robot_moving": 0,
    }


def test_task_latencies_are_split_by_whether_the_robot_met_people_while_on_the_task():
    scenario = cosim.load_scenario("warehouse-random", {**SMALL, "robots.driver": "tasks"})
    run = assemble(scenario).run
    records = HumanRecords(run, HumansConfig())
    book = run.service(TaskSourceAdapter).book
    book.tasks.clear()
    done = TaskStatus.DONE
    book.tasks[1] = Task(1, 1.0, 1.0, frozenset(), 0, done, None, "robot_1", 2, 3, s_to_ns(10))
    book.tasks[2] = Task(2, 1.0, 1.0, frozenset(), 0, done, None, "robot_2", 2, 3, s_to_ns(4))
    book.tasks[3] = Task(3, 1.0, 1.0, frozenset(), 0, TaskStatus.SERVING, None, "robot_1")
    records.met["robot_1"].append(s_to_ns(5))  # a near miss while on task 1
    records.met["robot_2"].append(s_to_ns(6))  # after task 2 was done
    summary = records.summary(run)
    assert summary["humans_tasks_met_people"] == 1
    assert summary["humans_task_latency_met_people_s"] == 10.0
    assert summary["humans_task_latency_clear_s"] == 4.0

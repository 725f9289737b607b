import numpy as np
import pandas as pd

from cosim.plotting.rundata import load_run, robot_order


def test_robot_names_come_in_fleet_order_numbers_compared_as_numbers_once_each():
    names = ["robot_10", "robot_2", "robot_1", "robot_2", "mocap", "robot_12"]
    assert robot_order(names) == ["mocap", "robot_1", "robot_2", "robot_10", "robot_12"]


def test_the_track_holds_every_robot_in_fleet_order_on_one_time_base(task_run):
    run = load_run(task_run)
    poses = pd.read_parquet(task_run / "tables" / "poses.parquet")
    assert run.track.robots == ("robot_1", "robot_2", "robot_3")
    assert run.track.x_m.shape == (poses["t_s"].nunique(), 3)
    last = poses[poses["robot"] == "robot_2"].iloc[-1]
    assert run.track.x_m[-1, 1] == last["x_m"] and run.track.yaw_rad[-1, 1] == last["yaw_rad"]


def test_the_rebuilt_world_is_the_runs_world(task_run):
    run = load_run(task_run)
    poses = pd.read_parquet(task_run / "tables" / "poses.parquet")
    first = poses[poses["t_s"] == 0.0][["x_m", "y_m"]].to_numpy()
    np.testing.assert_allclose(run.warehouse.starts[:, :2], first)


def test_a_task_claimed_but_not_served_at_the_end_is_held_by_the_robot_sent_to_it(task_run):
    tasks = load_run(task_run).tasks
    served = tasks["robot"] != ""
    assert (tasks.loc[served, "holder"] == tasks.loc[served, "robot"]).all()
    claimed = ~served & tasks["t_assigned_s"].notna()
    assert claimed.any(), "the fixture run should end with a task on its way"
    navigation = pd.read_parquet(task_run / "tables" / "navigation.parquet")
    goals = navigation[navigation["event"] == "goal"]
    for task in tasks[claimed].itertuples():
        sent = goals[(goals["goal_x_m"] == task.x_m) & (goals["goal_y_m"] == task.y_m)]
        assert task.holder in set(sent["robot"].astype(str))


def test_tables_the_run_lacks_or_that_are_empty_are_none(waypoint_run):
    run = load_run(waypoint_run)
    assert run.tasks is None and run.assignments is None
    assert run.messages is not None

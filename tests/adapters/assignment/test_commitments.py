import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pytest

from adapters.assignment.commitments import BLOCKED_S, RETRY_S, Commitments, RobotTasks
from adapters.assignment.tables import DtaRecords
from adapters.assignment.topics import ASSIGNMENT
from adapters.navigation.topics import goal_topic
from adapters.tasks.topics import CLAIMS, DONE, SERVICE_REQUESTS
from cosim.core.adapter import RunContext
from cosim.core.bus import Bus
from cosim.core.hosts import HostId
from cosim.core.kernel import Kernel
from cosim.core.messages import (
    Message,
    NavGoal,
    NavStatus,
    ServiceReply,
    ServiceRequest,
    TaskAssignment,
    TaskClaim,
    TaskDone,
    TaskInfo,
    TaskOrder,
)
from cosim.core.recorder import Recorder
from cosim.core.rng import RngStreams
from cosim.core.timebase import s_to_ns
from cosim.recording.dataframes import table_frame

NAMES = ["robot_1", "robot_2", "robot_3"]
TASKS = (TaskInfo(7, 3.0, 4.0, tuple(NAMES)), TaskInfo(8, 6.0, 8.0, tuple(NAMES)))
"""Task 7 is 5 m from the origin, task 8 is 10 m."""
DWELL_S = 2.0
REBROADCAST_S = 0.5


@dataclass
class Bench:
    """Every robot's commitments on a bus, and what they published (topic, message, host)."""

    run: RunContext
    duties: Commitments
    robots: list[RobotTasks]
    sent: list[tuple[str, Message, str]] = field(default_factory=list)

    def at(self, t_s: float) -> None:
        self.run.kernel.run(s_to_ns(t_s))

    def on(self, topic: str) -> list[Any]:
        messages = [m for t, m, _ in self.sent if t == topic]
        self.sent = [s for s in self.sent if s[0] != topic]
        return messages

    def events(self) -> list[tuple[str, str, str]]:
        frame = table_frame(self.run.recorder.events)
        return list(zip(frame.source, frame.kind, frame.detail, strict=True))


def bench(*, preemption: bool = False) -> Bench:
    kernel = Kernel()
    recorder = Recorder()
    run = RunContext(None, kernel, Bus(kernel, tap=recorder), RngStreams(1), recorder)  # type: ignore[arg-type]
    pose = np.zeros((len(NAMES), 2))
    duties = Commitments(
        NAMES,
        [HostId(n) for n in NAMES],
        pose,
        DtaRecords(recorder, NAMES),
        lambda x, y, task: math.hypot(task.x_m - x, task.y_m - y),
        dwell_ns=s_to_ns(DWELL_S),
        rebroadcast_ns=s_to_ns(REBROADCAST_S),
        preemption=preemption,
    )
    robots = [RobotTasks(i, name, epoch=4, tasks=TASKS) for i, name in enumerate(NAMES)]
    made = Bench(run, duties, robots)
    topics = [CLAIMS, SERVICE_REQUESTS, DONE, ASSIGNMENT] + [goal_topic(n) for n in NAMES]
    for topic in topics:
        run.bus.monitor(topic, lambda t, m, src, _now: made.sent.append((t, m, src)))
    return made


def heading(b: Bench, robot: int = 0, task: int = 0) -> RobotTasks:
    """Robot ``robot`` takes task index ``task`` (publications cleared)."""
    r = b.robots[robot]
    b.duties.act(b.run, r, task)
    b.sent.clear()
    return r


def test_a_robot_acting_on_a_task_claims_it_at_its_cost_and_drives_there():
    b = bench()
    r = b.robots[0]
    b.duties.act(b.run, r, 1)
    assert (r.phase, r.task, r.task_cost, r.goal_id) == ("heading", 8, 10.0, 1)
    [claim] = b.on(CLAIMS)
    assert claim == TaskClaim(0, 4, 8, "robot_1", 10.0, "claim")
    [goal] = b.on(goal_topic("robot_1"))
    assert (goal.goal_id, goal.x_m, goal.y_m) == (1, 6.0, 8.0)
    assert r.claims == {8: ("robot_1", 10.0)}
    assert all(src == "robot_1" for _, _, src in b.sent)


def test_a_decision_for_no_task_or_a_task_out_of_the_epoch_leaves_an_idle_robot_idle():
    b = bench()
    for decision in (None, 5):
        b.duties.act(b.run, b.robots[0], decision)
    assert b.robots[0].phase == "idle" and b.sent == []


def test_a_held_claim_is_repeated_every_rebroadcast_period_while_heading():
    b = bench()
    r = heading(b)
    for t_s in (0.2, 0.4, 0.5, 0.7, 1.0):
        b.at(t_s)
        b.duties.keep_promises(b.run, r, b.run.kernel.now_ns)
    claims = b.on(CLAIMS)
    assert [c.stamp_ns for c in claims] == [s_to_ns(0.5), s_to_ns(1.0)]
    assert all((c.task_id, c.state) == (7, "claim") for c in claims)


def test_the_same_decision_again_changes_nothing_and_without_preemption_a_heading_robot_stays():
    b = bench()
    r = heading(b)
    b.duties.act(b.run, r, 0)
    b.duties.act(b.run, r, 1)
    b.duties.act(b.run, r, None)
    assert (r.phase, r.task) == ("heading", 7) and b.sent == []


def test_with_preemption_a_heading_robot_gives_its_task_up_for_another():
    b = bench(preemption=True)
    r = heading(b)
    b.duties.act(b.run, r, 1)
    release, claim = b.on(CLAIMS)
    assert (release.task_id, release.state) == (7, "release")
    assert (claim.task_id, claim.state) == (8, "claim")
    [goal] = b.on(goal_topic("robot_1"))
    assert (goal.goal_id, goal.x_m, goal.y_m) == (2, 6.0, 8.0)
    assert (r.phase, r.task) == ("heading", 8)
    assert ("robot_1", "release", "task 7: re-assigned") in b.events()


def test_with_preemption_a_robot_reassigned_to_no_task_stops_driving_to_the_old_one():
    b = bench(preemption=True)
    r = heading(b)
    b.duties.act(b.run, r, None)
    [release] = b.on(CLAIMS)
    assert (release.task_id, release.state) == (7, "release")
    assert r.phase == "idle" and 7 not in r.claims
    [cancel] = b.on(goal_topic("robot_1"))  # its navigation must drop the old goal
    assert cancel.goal_id == 2 and math.isnan(cancel.x_m) and math.isnan(cancel.y_m)


def test_without_preemption_a_robot_still_gives_up_a_task_the_new_epoch_no_longer_has():
    """Another robot served it before its claim reached this one: a ghost, not a task."""
    b = bench()
    r = heading(b)  # task 7
    r.tasks = (TASKS[1],)  # the next epoch: task 7 is done
    b.duties.act(b.run, r, None)
    [release] = b.on(CLAIMS)
    assert (release.task_id, release.state) == (7, "release")
    [cancel] = b.on(goal_topic("robot_1"))
    assert math.isnan(cancel.x_m) and r.phase == "idle"
    assert ("robot_1", "release", "task 7: no longer open") in b.events()


def test_without_preemption_a_robot_gives_up_a_task_another_robot_holds_for_its_next():
    b = bench()
    r = heading(b)  # task 7
    r.tasks = (TaskInfo(7, 3.0, 4.0, tuple(NAMES), holder="robot_2"), TASKS[1])
    b.duties.act(b.run, r, 1)
    release, claim = b.on(CLAIMS)
    assert (release.task_id, release.state, claim.task_id) == (7, "release", 8)
    assert (r.phase, r.task) == ("heading", 8)
    assert ("robot_1", "release", "task 7: held by robot_2") in b.events()


def test_a_heading_robot_keeps_its_task_while_the_epoch_still_has_it_for_it():
    b = bench()
    r = heading(b)
    r.tasks = (TaskInfo(7, 3.0, 4.0, tuple(NAMES), holder="robot_1"), TASKS[1])
    b.duties.act(b.run, r, 1)
    assert (r.phase, r.task) == ("heading", 7) and b.sent == []


def test_a_cheaper_claim_on_the_same_task_wins_and_the_loser_gives_way():
    b = bench()
    r = heading(b)  # 5 m
    b.at(1.0)
    b.duties.on_claim(b.run, r, TaskClaim(0, 4, 7, "robot_3", 2.0, "claim"))
    assert (r.phase, r.task) == ("idle", -1)
    assert r.claims[7] == ("robot_3", 2.0)
    [cancel] = b.on(goal_topic("robot_1"))
    assert math.isnan(cancel.x_m) and cancel.goal_id == 2
    assert b.events() == [("robot_1", "conflict", "task 7 goes to robot_3")]


def test_a_dearer_claim_is_noted_but_the_robot_keeps_its_task():
    b = bench()
    r = heading(b)
    b.duties.on_claim(b.run, r, TaskClaim(0, 4, 7, "robot_2", 9.0, "claim"))
    assert (r.phase, r.task) == ("heading", 7) and b.sent == []
    assert r.claims[7] == ("robot_2", 9.0)


@pytest.mark.parametrize(("other", "wins"), [("robot_1", True), ("robot_3", False)])
def test_claims_of_equal_cost_go_to_the_robot_first_in_fleet_order(other, wins):
    b = bench()
    r = heading(b, robot=1)  # robot_2, 5 m
    b.duties.on_claim(b.run, r, TaskClaim(0, 4, 7, other, 5.0, "claim"))
    assert (r.phase == "idle") is wins


def test_a_robots_own_claim_coming_back_is_ignored():
    b = bench()
    r = heading(b)
    b.duties.on_claim(b.run, r, TaskClaim(0, 4, 7, "robot_1", 0.0, "claim"))
    assert r.phase == "heading" and r.claims == {7: ("robot_1", 5.0)}


def test_a_release_forgets_the_claim_only_of_the_robot_that_held_it():
    b = bench()
    r = b.robots[0]
    b.duties.on_claim(b.run, r, TaskClaim(0, 4, 8, "robot_2", 3.0, "claim"))
    b.duties.on_claim(b.run, r, TaskClaim(0, 4, 8, "robot_3", 0.0, "release"))
    assert r.claims == {8: ("robot_2", 3.0)}
    b.duties.on_claim(b.run, r, TaskClaim(0, 4, 8, "robot_2", 3.0, "release"))
    assert r.claims == {}


def test_at_the_task_the_robot_asks_for_service_at_once_and_again_every_retry_period():
    b = bench()
    r = heading(b)
    b.at(3.0)
    b.duties.on_nav(b.run, r, NavStatus(0, 1, "arrived", 3.0, 4.0, 0.0))
    assert r.phase == "requesting"
    for t_s in (3.5, 4.0, 4.5, 5.0):
        b.at(t_s)
        b.duties.keep_promises(b.run, r, b.run.kernel.now_ns)
    requests = b.on(SERVICE_REQUESTS)
    assert [q.stamp_ns for q in requests] == [s_to_ns(t) for t in (3.0, 4.0, 5.0)]
    assert all(q == ServiceRequest(q.stamp_ns, 7, "robot_1") for q in requests)
    assert RETRY_S == 1.0


def test_a_status_of_an_older_goal_or_of_an_idle_robot_is_ignored():
    b = bench()
    r = heading(b)
    b.duties.on_nav(b.run, r, NavStatus(0, 0, "arrived", 3.0, 4.0, 0.0))
    assert r.phase == "heading"
    idle = b.robots[1]
    b.duties.on_nav(b.run, idle, NavStatus(0, 0, "stuck", 0.0, 0.0, math.nan))
    assert idle.phase == "idle" and b.sent == []


@pytest.mark.parametrize("state", ["stuck", "unreachable"])
def test_a_robot_that_cannot_reach_its_task_releases_it_and_keeps_away_for_a_while(state):
    b = bench()
    r = heading(b)
    b.at(2.0)
    b.duties.on_nav(b.run, r, NavStatus(0, 1, state, 1.0, 1.0, math.nan))
    assert (r.phase, r.task) == ("idle", -1)
    assert r.blocked == {7: s_to_ns(2.0 + BLOCKED_S)}
    [release] = b.on(CLAIMS)
    assert (release.task_id, release.state, release.stamp_ns) == (7, "release", s_to_ns(2.0))
    assert b.events() == [("robot_1", "release", f"task 7: {state}")]


def test_granted_service_is_served_for_the_dwell_then_reported_until_acknowledged():
    b = bench()
    r = heading(b)
    b.duties.on_nav(b.run, r, NavStatus(0, 1, "arrived", 3.0, 4.0, 0.0))
    b.at(1.0)
    b.duties.on_reply(b.run, r, ServiceReply(0, 7, "robot_1", True))
    assert (r.phase, r.until_ns) == ("serving", s_to_ns(1.0 + DWELL_S))
    b.sent.clear()
    for t_s in (2.0, 2.9, 3.0, 3.5, 4.0):
        b.at(t_s)
        b.duties.keep_promises(b.run, r, b.run.kernel.now_ns)
    assert r.phase == "reporting"
    reports = b.on(DONE)
    assert [d.stamp_ns for d in reports] == [s_to_ns(3.0), s_to_ns(4.0)]
    assert all(d == TaskDone(d.stamp_ns, 7, "robot_1") for d in reports)
    assert b.on(SERVICE_REQUESTS) == []


def test_refused_service_frees_the_robot_and_forgets_its_claim():
    b = bench()
    r = heading(b)
    b.duties.on_nav(b.run, r, NavStatus(0, 1, "arrived", 3.0, 4.0, 0.0))
    b.duties.on_reply(b.run, r, ServiceReply(0, 7, "robot_1", False))
    assert (r.phase, r.task, r.claims) == ("idle", -1, {})
    assert b.events() == [("robot_1", "release", "task 7: refused")]


def test_a_reply_about_another_task_or_to_a_robot_not_asking_is_ignored():
    b = bench()
    r = heading(b)
    b.duties.on_reply(b.run, r, ServiceReply(0, 7, "robot_1", True))  # not at the task yet
    assert r.phase == "heading"
    b.duties.on_nav(b.run, r, NavStatus(0, 1, "arrived", 3.0, 4.0, 0.0))
    b.duties.on_reply(b.run, r, ServiceReply(0, 8, "robot_1", True))
    assert r.phase == "requesting"


def test_a_robot_at_its_task_finishes_it_whatever_its_protocol_decides_later():
    b = bench(preemption=True)
    r = heading(b)
    b.duties.on_nav(b.run, r, NavStatus(0, 1, "arrived", 3.0, 4.0, 0.0))
    b.sent.clear()
    b.duties.act(b.run, r, 1)
    b.duties.act(b.run, r, None)
    assert (r.phase, r.task) == ("requesting", 7) and b.sent == []


def test_an_idle_robot_ordered_by_the_base_station_takes_the_task_and_says_so():
    b = bench()
    r = b.robots[2]
    b.at(1.5)
    b.duties.on_order(b.run, r, TaskOrder(0, 4, "robot_3", 8, 4.5))
    assert (r.phase, r.task, r.task_cost) == ("heading", 8, 4.5)
    [decision] = b.on(ASSIGNMENT)
    assert decision == TaskAssignment(s_to_ns(1.5), 4, "robot_3", 8, 4.5, 0)
    assert [c.task_id for c in b.on(CLAIMS)] == [8]
    assert isinstance(b.on(goal_topic("robot_3"))[0], NavGoal)


@pytest.mark.parametrize(
    "order",
    [TaskOrder(0, 4, "robot_1", 8, 1.0), TaskOrder(0, 4, "robot_3", 99, 1.0)],
    ids=["for another robot", "an unknown task"],
)
def test_an_order_for_another_robot_or_task_is_ignored(order):
    b = bench()
    b.duties.on_order(b.run, b.robots[2], order)
    assert b.robots[2].phase == "idle" and b.sent == []


def test_a_busy_robot_ignores_orders():
    b = bench()
    r = heading(b, robot=2)
    b.duties.on_order(b.run, r, TaskOrder(0, 4, "robot_3", 8, 1.0))
    assert (r.phase, r.task) == ("heading", 7) and b.sent == []

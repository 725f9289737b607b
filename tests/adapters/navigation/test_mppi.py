"""The ``mppi`` local controller: settings, per-robot sequences, seeds, and real runs."""

from __future__ import annotations

import numpy as np
import pytest

import adapters.navigation.mppi as mppi_adapter
import cosim
from adapters.navigation.contract import CONTROLLERS, ControlInputs, ControllerContext
from adapters.navigation.mppi import Mppi, MppiSettings
from cosim.core.errors import ConfigError
from cosim.core.rng import RngStreams
from cosim.scenario.model import section_registry
from cosim.testing import assert_no_collisions, assert_same_run, run_scenario
from models.fleet.kinematics import DriveLimits
from models.navigation.traffic import MovingPoints

LIMITS = DriveLimits(1.0, 0.3, 2.0, 2.0, 3.0)
NO_MOVING = MovingPoints(np.zeros(0, np.int64), np.zeros((0, 2)), np.zeros(0), np.zeros(0))
MPPI = {"navigation.controller": "mppi"}


class _Run:
    """What the controller asks of a run: its settings and a random stream."""

    def __init__(self, seed: int, settings: MppiSettings) -> None:
        self.rng = RngStreams(seed)
        self._settings = settings

    def settings(self, kind):
        assert kind is MppiSettings
        return self._settings


def _controller(n, seed=1, control_hz=10.0, **settings):
    run = _Run(seed, MppiSettings(**settings))
    return Mppi(ControllerContext(run, LIMITS, np.full(n, 0.33), control_hz))  # type: ignore[arg-type]


def _inputs(pose, carrots, goals=None, points=None):
    n = len(pose)
    hits = points or [[] for _ in range(n)]
    start = np.cumsum([0, *(len(h) for h in hits)]).astype(np.int64)
    return ControlInputs(
        pose=np.array(pose, dtype=float),
        vel=np.zeros((n, 2)),
        carrots=np.array(carrots, dtype=float),
        goals=np.add(goals if goals is not None else carrots, (20.0, 0.0)),
        points=np.array([p for h in hits for p in h], dtype=float).reshape(-1, 2),
        start=start,
        moving=NO_MOVING,
        discs=np.zeros((0, 3)),
        disc_start=np.zeros(n + 1, dtype=np.int64),
        now_ns=0,
    )


def test_mppi_is_registered_with_its_settings_section():
    assert CONTROLLERS.installed().get("mppi") is Mppi
    assert section_registry().get("mppi") is MppiSettings


def test_the_controller_keeps_its_padding_and_a_sequence_per_robot():
    control = _controller(3, control_hz=20.0, time_steps=12, footprint_padding_m=0.15)
    assert control.footprint_padding_m == 0.15
    assert control.params.control_period_s == 0.05 and control.params.time_steps == 12
    assert control.nominal.shape == (3, 12, 2)
    v, w, blocked = control.commands(_inputs([[0.0, 0.0, 0.0]] * 3, [[2.0, 0.0]] * 3))
    assert v.shape == w.shape == blocked.shape == (3,) and blocked.dtype == bool
    assert control.nominal.any()


def test_the_same_seed_gives_the_same_commands_and_another_seed_others():
    inputs = _inputs([[0.0, 0.0, 0.0], [5.0, 0.0, 1.0]], [[2.0, 1.0], [5.0, 2.0]])
    runs = {}
    for name, seed in [("first", 4), ("again", 4), ("other", 5)]:
        control = _controller(2, seed=seed)
        runs[name] = [control.commands(inputs) for _ in range(3)]
    for tick in range(3):
        for a, b in zip(runs["first"][tick], runs["again"][tick], strict=True):
            assert np.array_equal(a, b)
    assert not np.array_equal(runs["first"][0][1], runs["other"][0][1])


def test_a_robot_whose_goal_moves_starts_its_sequence_again(monkeypatch):
    seen = []
    real = mppi_adapter.mppi_batch

    def spy(*args, **kwargs):
        seen.append(args[10].copy())  # the nominal sequences handed in
        return real(*args, **kwargs)

    monkeypatch.setattr(mppi_adapter, "mppi_batch", spy)
    control = _controller(3, goal_reset_m=0.1)
    pose, carrots = (
        [[0.0, 0.0, 0.0], [0.0, 5.0, 0.0], [0.0, 9.0, 0.0]],
        [[2.0, 0.0], [2.0, 5.0], [2.0, 9.0]],
    )
    for _ in range(3):
        control.commands(_inputs(pose, carrots))
    assert not seen[0].any()  # no goal before: every robot starts from zeros
    assert np.abs(seen[2]).sum(axis=(1, 2)).min() > 0.0
    goals = np.add(carrots, [[1.0, 0.0], [0.05, 0.0], [0.0, 0.0]])  # moved, nudged, kept
    control.commands(_inputs(pose, carrots, goals=goals))
    assert not seen[3][0].any()
    assert seen[3][1].any() and seen[3][2].any()


def test_bad_settings_are_refused_by_name():
    with pytest.raises(ConfigError, match=r"samples = 0.*>= 1"):
        cosim.load_scenario("warehouse-random", {"mppi.samples": 0})
    with pytest.raises(ConfigError, match=r"temperature = 0.*> 0"):
        cosim.load_scenario("warehouse-random", {"mppi.temperature": 0.0})


def test_robots_reach_goals_on_warehouse_random_without_touching_anything():
    result = run_scenario("warehouse-random", MPPI, duration_s=60)
    assert_no_collisions(result)
    assert result.summary["collisions"] == 0 and result.summary["near_misses"] == 0
    assert result.summary["arrivals"] >= 6
    assert result.summary["controller_commands_clipped"] == 0
    again = run_scenario("warehouse-random", MPPI, duration_s=60)
    assert_same_run(result, again)


def test_a_run_is_the_same_on_one_thread_or_two():
    scenario = cosim.load_scenario("warehouse-random", MPPI)
    one = cosim.run(scenario, seed=3, duration_s=20.0, threads=1)
    two = cosim.run(scenario, seed=3, duration_s=20.0, threads=2)
    assert_same_run(one, two)
    assert one.summary["arrivals"] >= 1

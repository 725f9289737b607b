"""One robot's lidar beams, cast again from the run's world, robots and people."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import cosim
from adapters.world.warehouse import scenario_warehouse
from cosim.plotting.rays import LidarRays
from cosim.plotting.rundata import RunData, Track, load_run

RANGE_MAX_M = 10.0


def test_lidar_rays_stop_at_what_they_hit_and_reach_range_max_otherwise(task_run):
    run = load_run(task_run)
    rays = LidarRays(run, 0, max_rays=45)
    origin, ends, hit = rays.cast(0)
    assert len(ends) == 45  # the 90 beams of the scenario, every second one
    lengths = ((ends - origin) ** 2).sum(axis=1) ** 0.5
    assert (lengths[hit] < run.scenario.lidar.range_max_m).all()
    assert (abs(lengths[~hit] - run.scenario.lidar.range_max_m) < 1e-9).all()
    assert hit.any()  # a 12 m hall: walls within 10 m in most directions


def _hall(
    x_m: list[float],
    y_m: list[float],
    *,
    beams: int = 360,
    humans: pd.DataFrame | None = None,
) -> RunData:
    """An empty 12 m x 12 m hall, robots at (x, y) heading east, one pose sample."""
    overrides = {
        "world.shelf_count": 0,
        "world.size_m": [12.0, 12.0],
        "robots.count": len(x_m),
        "lidar.beams": beams,
        "lidar.range_max_m": RANGE_MAX_M,
    }
    scenario = cosim.load_scenario("warehouse-random", overrides)
    track = Track(
        robots=tuple(f"robot_{k + 1}" for k in range(len(x_m))),
        t_s=np.array([0.0]),
        x_m=np.array([x_m], dtype=float),
        y_m=np.array([y_m], dtype=float),
        yaw_rad=np.zeros((1, len(x_m))),
    )
    return RunData(
        Path("."), scenario, scenario_warehouse(scenario), track, None, None, None, humans
    )


def _reach(rays: LidarRays, origin: np.ndarray, ends: np.ndarray, bearing: float) -> float:
    """How far the beam nearest ``bearing`` (rad, in map) reaches (m)."""
    k = int(np.argmin(np.abs(np.angle(np.exp(1j * (rays.angles - bearing))))))
    return float(np.hypot(*(ends[k] - origin)))


def test_a_beam_stops_at_another_robot_s_disc_and_passes_out_of_its_own():
    run = _hall([3.0, 6.0], [6.0, 6.0])
    rays = LidarRays(run, 0, max_rays=360)
    origin, ends, hit = rays.cast(0)
    radius = run.scenario.robots.radius_m
    np.testing.assert_allclose(origin, [3.0, 6.0])
    assert _reach(rays, origin, ends, 0.0) == pytest.approx(3.0 - radius, abs=1e-6)  # robot_2
    assert _reach(rays, origin, ends, math.pi) == pytest.approx(3.0, abs=1e-6)  # the west wall
    # toward the far north-east corner, 10.8 m away, the beam reaches range_max and no more
    corner = math.atan2(12.0 - 6.0, 12.0 - 3.0)
    assert _reach(rays, origin, ends, corner) == pytest.approx(RANGE_MAX_M)
    k = int(np.argmin(np.abs(rays.angles - corner)))
    assert not hit[k] and hit[int(np.argmin(np.abs(rays.angles - math.pi / 2)))]


def test_a_beam_stops_at_a_person_sampled_at_or_before_the_pose():
    humans = pd.DataFrame(
        {"t_s": [0.0], "id": ["p1"], "kind": ["person"], "x_m": [3.0], "y_m": [8.0],
         "yaw_rad": [0.0]}
    )  # fmt: skip
    run = _hall([3.0], [6.0], humans=humans)
    rays = LidarRays(run, 0, max_rays=360)
    origin, ends, _ = rays.cast(0)
    worker = run.scenario.humans.worker_radius_m
    assert _reach(rays, origin, ends, math.pi / 2) == pytest.approx(2.0 - worker, abs=1e-6)
    without = LidarRays(_hall([3.0], [6.0]), 0, max_rays=360)
    origin, ends, _ = without.cast(0)
    assert _reach(without, origin, ends, math.pi / 2) == pytest.approx(6.0, abs=1e-6)


def test_every_kth_beam_is_drawn_up_to_max_rays():
    run = _hall([3.0], [6.0], beams=90)
    assert len(LidarRays(run, 0, max_rays=1000).angles) == 90
    assert len(LidarRays(run, 0, max_rays=30).angles) == 30
    assert len(LidarRays(run, 0, max_rays=40).angles) == 30  # every 3rd beam of 90


def test_no_beam_without_a_lidar_or_without_a_pose():
    origin, ends, hit = LidarRays(_hall([3.0], [6.0], beams=0), 0).cast(0)
    assert ends.shape == (0, 2) and hit.shape == (0,)
    lost = _hall([3.0, np.nan], [6.0, np.nan])
    origin, ends, hit = LidarRays(lost, 1).cast(0)
    assert np.isnan(origin).all() and ends.shape == (0, 2)
    _, ends, _ = LidarRays(lost, 0, max_rays=360).cast(0)  # a robot without pose hides nothing
    assert len(ends) == 360

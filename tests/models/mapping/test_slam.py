import math

import numpy as np
import pytest

from models.geometry.se2 import compose, inverse, relative
from models.mapping.grid import LogOddsMap, MapGeometry
from models.mapping.loop_params import LoopParams
from models.mapping.slam import MapperParams, ScanMapper, UpdateGate
from tests.models.mapping.conftest import GEOMETRY, Lidar

# a 30 m corridor, 2.4 m wide, with door frames every 3 m so that it has features along it
CORRIDOR = np.array(
    [[-1.0, -1.4, 31.0, -1.2], [-1.0, 1.2, 31.0, 1.4], [-1.2, -1.4, -1.0, 1.4]]
    + [[3.0 * k, 0.9, 3.0 * k + 0.2, 1.2] for k in range(1, 10)]
    + [[3.0 * k + 1.5, -1.2, 3.0 * k + 1.7, -0.9] for k in range(0, 10)]
)


def _drive(drift_per_m: float, matching: bool, loops: bool = False):
    """Drive along the corridor and back; odometry under-turns by ``drift_per_m`` rad/m."""
    lidar = Lidar(CORRIDOR)
    geometry = MapGeometry.covering((-1.2, -1.4, 31.0, 1.4), 0.05, 1.0)
    params = MapperParams(
        gate=UpdateGate(0.3, 0.3, 0.0),
        scan_matching=matching,
        loop_closure=LoopParams() if loops else None,
    )
    truth = [(0.5 + 0.1 * k, 0.0, 0.0) for k in range(280)]
    truth += [(28.5, 0.0, 0.1 * k * math.pi) for k in range(1, 11)]
    truth += [(28.5 - 0.1 * k, 0.0, math.pi) for k in range(1, 280)]
    mapper = ScanMapper(LogOddsMap(geometry), truth[0], params, GEOMETRY.angles())
    odom = truth[0]
    errors, odom_errors = [], []
    for k, pose in enumerate(truth):
        if k:
            step = relative(truth[k - 1], pose)
            travelled = math.hypot(step[0], step[1])
            odom = compose(odom, (step[0] * 1.01, step[1], step[2] - drift_per_m * travelled))
        mapper.process(k * 100_000_000, odom, lidar.scan(pose))
        estimate = mapper.estimate(odom)
        errors.append(math.hypot(estimate[0] - pose[0], estimate[1] - pose[1]))
        odom_errors.append(math.hypot(odom[0] - pose[0], odom[1] - pose[1]))
    return np.array(errors), np.array(odom_errors), mapper


def test_a_corridor_driven_with_known_drift_is_corrected_by_matching():
    errors, odom_errors, mapper = _drive(0.01, matching=True)
    assert odom_errors.max() > 2.0, "the drift must be real for the test to mean anything"
    assert errors.max() < 0.15
    assert mapper.matched >= mapper.updates - 1


def test_without_matching_the_estimate_is_the_odometry():
    errors, odom_errors, mapper = _drive(0.01, matching=False)
    assert np.allclose(errors, odom_errors)
    assert mapper.matched == 0


def test_scans_update_the_map_only_after_enough_travel_turn_and_time():
    gate = UpdateGate(min_travel_m=0.5, min_heading_rad=0.5, min_interval_s=1.0)
    assert not gate.due((0.4, 0.0, 0.4), 2.0)
    assert gate.due((0.5, 0.0, 0.0), 2.0)
    assert gate.due((0.0, 0.0, -0.5), 2.0)
    assert not gate.due((3.0, 0.0, 0.0), 0.5)


def test_the_correction_maps_odometry_onto_the_estimate():
    _, _, mapper = _drive(0.01, matching=True)
    odom = (3.0, -1.0, 0.3)
    assert np.allclose(mapper.estimate(odom), compose(mapper.correction, odom))
    assert np.allclose(compose(mapper.correction, inverse(mapper.correction)), (0, 0, 0))


@pytest.mark.slow
def test_loop_closure_adds_nothing_where_matching_kept_the_corridor_straight():
    errors, _, mapper = _drive(0.01, matching=True, loops=True)
    plain, _, _ = _drive(0.01, matching=True)
    assert mapper.loops is not None
    assert mapper.loops.not_needed > 0  # the way back was recognised, and agreed already
    assert mapper.loops.closures == 0
    assert np.array_equal(errors, plain)

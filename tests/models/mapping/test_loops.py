"""The checks a loop closure passes before and after it enters the pose graph."""

import math

import numpy as np
import pytest

from models.geometry.se2 import compose, relative
from models.mapping.loops import LoopCloser, LoopParams
from models.mapping.posegraph import Edge, sqrt_information

ANGLES = np.linspace(-math.pi, math.pi, 8, endpoint=False)
MATCHED = np.diag([0.02**2, 0.02**2, 0.005**2])  # a scan match's covariance


def _out_and_back() -> LoopCloser:
    """40 nodes: 10 m east in 0.5 m steps, a U-turn, and back west 2 m to the north."""
    closer = LoopCloser(
        LoopParams(), ANGLES, range_min_m=0.1, range_max_m=10.0, clear_no_return_m=3.0
    )
    poses = [(0.5 * k, 0.0, 0.0) for k in range(20)] + [
        (9.5 - 0.5 * k, 2.0, math.pi) for k in range(20)
    ]
    for pose in poses:
        closer.add(pose, pose, np.full(len(ANGLES), 5.0, np.float32), True, MATCHED)
    return closer


def _closure(closer: LoopCloser, a: int, b: int, error=(0.0, 0.0, 0.0), sigma_m=0.05) -> Edge:
    """Node ``b`` seen from node ``a``, off from where the graph has it by ``error``."""
    z = compose(relative(closer.graph.nodes[a], closer.graph.nodes[b]), error)
    cov = np.diag([sigma_m**2, sigma_m**2, 0.02**2])
    return Edge(a, b, z, 0.0, 0.0, sqrt_information(cov))


def test_a_closure_the_path_could_have_drifted_into_is_plausible():
    closer = _out_and_back()
    assert closer._plausible(_closure(closer, 2, 37, (0.3, -0.2, 0.03)))


def test_a_closure_asking_for_more_drift_than_the_path_allows_is_not():
    closer = _out_and_back()
    # 30 m of matched steps cannot have drifted 4 m: that place only looks the same
    assert not closer._plausible(_closure(closer, 2, 37, (4.0, 0.0, 0.0)))


def test_a_closure_the_estimate_already_agrees_with_corrects_nothing():
    closer = _out_and_back()
    assert closer._correction(_closure(closer, 2, 37, (0.02, 0.0, 0.0))) < 1.0
    assert closer._correction(_closure(closer, 2, 37, (0.3, 0.0, 0.0))) > 16.0


def test_two_closures_of_one_revisit_agree_and_an_aliased_one_does_not():
    closer = _out_and_back()
    drifted = (0.4, -0.1, 0.02)
    first = _closure(closer, 2, 35, drifted)
    again = _closure(closer, 3, 36, drifted)
    aliased = _closure(closer, 3, 36, (1.5, -0.1, 0.02))  # a door frame 1.1 m further on
    assert closer._agree(first, again)
    assert not closer._agree(first, aliased)


def test_a_corridor_match_constrains_nothing_along_the_corridor():
    closer = _out_and_back()
    along_x = np.diag([0.3**2, 0.02**2, 0.01**2])  # the match's spread, map axes
    edge = closer._closure(2, 37, closer.graph.nodes[37], along_x)
    covariance = np.linalg.inv(edge.whitening().T @ edge.whitening())
    assert math.sqrt(covariance[0, 0]) == pytest.approx(LoopParams().ambiguous_sigma_m)
    assert math.sqrt(covariance[1, 1]) == pytest.approx(0.02)


def test_a_step_is_as_sure_as_odometry_and_matching_together():
    closer = _out_and_back()
    fused = np.linalg.inv(closer.steps[5])
    odometry = np.linalg.inv(closer._odometry_covariance((0.5, 0.0, 0.0)))
    assert np.allclose(fused, odometry + np.linalg.inv(MATCHED))


def test_the_chain_covariance_grows_with_the_path_and_its_lever():
    closer = _out_and_back()
    near, far = closer._chain_covariance(0, 5), closer._chain_covariance(0, 19)
    along, sideways = far[0, 0] / near[0, 0], far[1, 1] / near[1, 1]
    assert along == pytest.approx(19 / 5, rel=0.01)  # step variances add up
    assert sideways > 2 * along  # and heading errors swing the far end further
    assert np.all(np.linalg.eigvalsh(far) > 0)

"""The checks a loop closure passes before and after it enters the pose graph."""

import numpy as np

from models.mapping.closure_checks import ClosureChecks
from models.mapping.loop_params import LoopParams
from tests.models.mapping.conftest import closure, out_and_back


def _checks(params: LoopParams | None = None) -> ClosureChecks:
    return ClosureChecks(out_and_back(), params or LoopParams())


def test_a_closure_the_path_could_have_drifted_into_is_plausible():
    checks = _checks()
    assert checks.plausible(closure(checks.updates, 2, 37, (0.3, -0.2, 0.03)))


def test_a_closure_asking_for_more_drift_than_the_path_allows_is_not():
    checks = _checks()
    # 30 m of matched steps cannot have drifted 4 m: that place only looks the same
    assert not checks.plausible(closure(checks.updates, 2, 37, (4.0, 0.0, 0.0)))


def test_a_closure_the_estimate_already_agrees_with_corrects_nothing():
    checks = _checks()
    assert checks.correction(closure(checks.updates, 2, 37, (0.02, 0.0, 0.0))) < 1.0
    assert checks.correction(closure(checks.updates, 2, 37, (0.3, 0.0, 0.0))) > 16.0


def test_two_closures_of_one_revisit_agree_and_an_aliased_one_does_not():
    checks = _checks()
    drifted = (0.4, -0.1, 0.02)
    first = closure(checks.updates, 2, 35, drifted)
    again = closure(checks.updates, 3, 36, drifted)
    aliased = closure(checks.updates, 3, 36, (1.5, -0.1, 0.02))  # a door frame 1.1 m further on
    assert checks.agree(first, again)
    assert not checks.agree(first, aliased)


def _residuals(closure_chi2: float, others: float = 1.0) -> np.ndarray:
    """Per edge of the out-and-back graph with one closure added: squared whitened residuals."""
    return np.array([others] * 39 + [closure_chi2])


def test_a_solution_whose_closure_residual_is_beyond_the_gate_is_not_consistent():
    checks = _checks()
    checks.updates.loop_edges.append(True)  # the closure is the graph's last edge
    cost = float(_residuals(0.0).sum())
    assert checks.consistent(_residuals(16.0), cost, 1)
    assert not checks.consistent(_residuals(16.5), cost, 1)  # 16.27: chi-square 99.9 %, 3 dof


def test_a_solution_raising_the_whole_cost_further_than_its_closures_explain_is_not_consistent():
    checks = _checks()
    checks.updates.loop_edges.append(True)
    before = float(_residuals(0.0).sum())
    # every edge a little worse: no single residual is off, all together they are
    bent = _residuals(1.0, others=1.5)
    assert not checks.consistent(bent, before, 1)
    assert checks.consistent(bent, before, 2)  # two closures may raise it further (22.46)

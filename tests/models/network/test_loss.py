import math

import numpy as np
import pytest

from models.errors import ModelError
from models.network.loss import BernoulliLoss, GilbertElliottLoss, NoLoss


def _run(process, n, seed):
    """Loss indicators of n packets, two uniforms per packet from one seeded stream."""
    uniforms = np.random.default_rng(seed).random((n, 2)).tolist()
    return np.array([process.lost(u_tr, u_loss) for u_tr, u_loss in uniforms])


def _mean_burst(lost):
    starts = int(lost[0]) + int(np.sum(lost[1:] & ~lost[:-1]))
    return lost.sum() / starts


def test_gilbert_elliott_matches_its_analytic_loss_rate_and_burst_length():
    # Tolerance 3 % relative: about 4 standard errors at 300k packets (spread over 8 seeds:
    # 0.7 % for the loss rate, 0.6 % for the burst length).
    process = GilbertElliottLoss(0.05, 0.3, loss_good=0.01, loss_bad=0.8)
    lost = _run(process, 300_000, seed=11)
    assert process.stationary_loss() == pytest.approx((6 / 7) * 0.01 + (1 / 7) * 0.8)
    assert lost.mean() == pytest.approx(process.stationary_loss(), rel=0.03)
    assert _mean_burst(lost) == pytest.approx(process.mean_burst_length(), rel=0.03)


def test_the_simple_gilbert_model_has_mean_burst_length_one_over_r():
    process = GilbertElliottLoss(0.02, 0.25)
    assert process.mean_burst_length() == pytest.approx(4.0)
    assert process.stationary_loss() == pytest.approx(0.02 / 0.27)
    lost = _run(process, 300_000, seed=12)
    # the loss rate of a bursty process varies more: 2 % per seed, tolerance 6 %
    assert lost.mean() == pytest.approx(process.stationary_loss(), rel=0.06)
    assert _mean_burst(lost) == pytest.approx(4.0, rel=0.03)


def test_gemodel_with_only_p_is_bernoulli_loss_as_in_tc_netem():
    process = GilbertElliottLoss(0.1)
    assert (process.r, process.loss_good, process.loss_bad) == (0.9, 0.0, 1.0)
    assert process.stationary_loss() == pytest.approx(0.1)
    assert process.mean_burst_length() == pytest.approx(1 / 0.9)
    assert BernoulliLoss(0.1).mean_burst_length() == pytest.approx(1 / 0.9)


def test_a_packet_is_decided_by_the_state_it_started_in_as_in_netem():
    # p = 1: every packet moves Good -> Bad, but the first packet still goes out in Good
    process = GilbertElliottLoss(1.0, 0.0)
    assert process.lost(0.5, 0.5) is False
    assert process.bad
    assert process.lost(0.5, 0.5) is True
    assert process.mean_burst_length() == math.inf


def test_bernoulli_loss_compares_the_loss_uniform_with_p():
    process = BernoulliLoss(0.25)
    assert process.lost(0.0, 0.2499) is True
    assert process.lost(0.0, 0.25) is False
    assert BernoulliLoss(1.0).lost(0.0, 0.999999) is True
    assert BernoulliLoss(0.0).lost(0.0, 0.0) is False


def test_no_loss_never_loses():
    assert NoLoss().lost(0.0, 0.0) is False
    assert NoLoss().stationary_loss() == 0.0


def test_a_process_that_never_loses_has_no_bursts():
    assert GilbertElliottLoss(0.1, 0.1, loss_good=0.0, loss_bad=0.0).mean_burst_length() == 0.0
    assert GilbertElliottLoss(0.0, 0.0, loss_good=0.2).stationary_loss() == pytest.approx(0.2)


@pytest.mark.parametrize(
    ("make", "key"),
    [
        (lambda: BernoulliLoss(1.5), "network.loss_prob"),
        (lambda: BernoulliLoss(-0.1), "network.loss_prob"),
        (lambda: BernoulliLoss(float("nan")), "network.loss_prob"),
        (lambda: GilbertElliottLoss(1.1, 0.5), "network.ge_p"),
        (lambda: GilbertElliottLoss(0.1, -0.5), "network.ge_r"),
        (lambda: GilbertElliottLoss(0.1, 0.5, loss_good=2.0), "network.ge_loss_good"),
        (lambda: GilbertElliottLoss(0.1, 0.5, loss_bad=-1.0), "network.ge_loss_bad"),
    ],
)
def test_a_probability_outside_0_1_is_refused_with_its_key(make, key):
    with pytest.raises(ModelError) as error:
        make()
    assert error.value.key == key

"""The built-in loss models of the links backend, built from ``[network]``."""

from __future__ import annotations

import numpy as np
import pytest

import cosim
from adapters.network.loss import Bernoulli, GilbertElliott, Lossless
from cosim.core.errors import ConfigError
from models.errors import ModelError
from models.network.loss import BernoulliLoss, GilbertElliottLoss, NoLoss
from tests.conftest import SMALL


def _losses(process, n: int, seed: int = 1) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return np.array([process.lost(*rng.random(2)) for _ in range(n)])


def test_no_loss_makes_links_that_never_lose_a_message(context):
    make = Lossless(context()).factory()
    assert make is NoLoss
    assert not _losses(make(), 1000).any()


def test_bernoulli_links_lose_loss_prob_of_messages_each_on_its_own(context):
    make = Bernoulli(context(loss_model="bernoulli", loss_prob=0.2)).factory()
    first, second = make(), make()
    assert first == second == BernoulliLoss(0.2) and first is not second
    assert _losses(first, 20_000).mean() == pytest.approx(0.2, abs=0.01)
    assert first.stationary_loss() == pytest.approx(0.2)


@pytest.mark.parametrize("prob", [-0.1, 1.5, float("nan")])
def test_a_bernoulli_probability_out_of_range_is_refused_when_built(context, prob):
    with pytest.raises(ModelError, match=r"network\.loss_prob"):
        Bernoulli(context(loss_model="bernoulli", loss_prob=prob))


def test_gilbert_elliott_takes_netems_parameters_and_starts_each_link_good(context):
    cfg = {"ge_p": 0.05, "ge_r": 0.2, "ge_loss_good": 0.01, "ge_loss_bad": 0.9}
    make = GilbertElliott(context(loss_model="gilbert_elliott", **cfg)).factory()
    process = make()
    assert isinstance(process, GilbertElliottLoss)
    assert (process.p, process.r, process.loss_good, process.loss_bad) == (0.05, 0.2, 0.01, 0.9)
    assert not process.bad
    _losses(process, 200)
    assert not make().bad  # a new link starts good, whatever the others went through
    assert make() is not make()


def test_gilbert_elliott_loses_in_bursts_at_its_long_run_rate(context):
    # netem gemodel with 1-h = 1, 1-k = 0: loss p / (p + r), bursts of 1 / r on average
    make = GilbertElliott(context(loss_model="gilbert_elliott", ge_p=0.05, ge_r=0.2)).factory()
    lost = _losses(make(), 100_000, seed=4)
    assert lost.mean() == pytest.approx(0.05 / 0.25, abs=0.01)
    edges = np.flatnonzero(np.diff(np.r_[0, lost.astype(int), 0]))
    bursts = edges[1::2] - edges[::2]
    assert bursts.mean() == pytest.approx(1 / 0.2, rel=0.1)


@pytest.mark.parametrize("key", ["ge_p", "ge_r", "ge_loss_good", "ge_loss_bad"])
def test_a_gilbert_elliott_parameter_out_of_range_is_refused_when_built(context, key):
    with pytest.raises(ModelError, match=rf"network\.{key}"):
        GilbertElliott(context(loss_model="gilbert_elliott", **{key: 1.5}))


def test_a_loss_prob_is_refused_unless_the_loss_model_is_bernoulli():
    for model in ("none", "gilbert_elliott"):
        with pytest.raises(ConfigError) as refused:
            cosim.load_scenario(
                "warehouse-random",
                {**SMALL, "network.loss_model": model, "network.loss_prob": 0.2},
            )
        assert (
            f"loss_prob = 0.2: expected 0 with loss_model '{model}' (only 'bernoulli' read "
            "loss_prob)"
        ) in str(refused.value)
    scenario = cosim.load_scenario(
        "warehouse-random", {**SMALL, "network.loss_model": "bernoulli", "network.loss_prob": 0.2}
    )
    assert scenario.network.loss_prob == 0.2

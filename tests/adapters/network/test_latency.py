"""The built-in latency models of the links backend, built from ``[network]``."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import cosim
from adapters.network.latency import Constant, Empirical, Lognormal, Normal
from cosim.core.errors import ConfigError
from models.errors import ModelError
from models.network.latency import (
    ConstantLatency,
    EmpiricalLatency,
    LognormalLatency,
    NormalLatency,
)
from tests.conftest import SMALL


def _load(**network: object) -> cosim.Scenario:
    return cosim.load_scenario("warehouse-random", {**SMALL, **network})


def test_constant_delays_every_message_by_exactly_latency_ms_in_ns(context):
    model = Constant(context(latency_ms=5.0)).model()
    assert model == ConstantLatency(5.0)
    draws = model.sample(np.random.default_rng(1), 50)
    assert draws.dtype == np.int64 and set(draws.tolist()) == {5_000_000}


def test_normal_draws_round_latency_ms_with_jitter_ms_and_never_below_zero(context):
    model = Normal(context(latency_ms=3.0, jitter_ms=1.0)).model()
    assert model == NormalLatency(3.0, 1.0)
    draws = model.sample(np.random.default_rng(1), 20_000) / 1e6
    assert draws.min() >= 0
    assert draws.mean() == pytest.approx(model.truncated_mean_ms, abs=0.03)
    assert draws.std() == pytest.approx(0.97, abs=0.05)  # cut at 0: a little under 1 ms


def test_lognormal_has_the_mean_and_deviation_asked_for_and_a_long_tail(context):
    model = Lognormal(context(latency_ms=20.0, jitter_ms=10.0)).model()
    assert model == LognormalLatency(20.0, 10.0)
    draws = model.sample(np.random.default_rng(2), 50_000) / 1e6
    assert draws.mean() == pytest.approx(20.0, rel=0.02)
    assert draws.std() == pytest.approx(10.0, rel=0.05)
    assert np.median(draws) < draws.mean()  # skewed right


def test_empirical_draws_only_the_measured_delays_of_its_csv(context, tmp_path: Path):
    csv = tmp_path / "delays.csv"
    csv.write_text("delay_ms\n1.5\n4\n10\n")
    model = Empirical(context(latency_model="empirical", latency_csv=str(csv))).model()
    assert isinstance(model, EmpiricalLatency)
    assert model.samples_ms.tolist() == [1.5, 4.0, 10.0]
    draws = model.sample(np.random.default_rng(3), 300)
    assert set(draws.tolist()) == {1_500_000, 4_000_000, 10_000_000}


def test_empirical_refuses_a_missing_file_naming_the_key_and_the_path(context, tmp_path: Path):
    missing = tmp_path / "none.csv"
    with pytest.raises(ModelError) as refused:
        Empirical(context(latency_model="empirical", latency_csv=str(missing)))
    assert "network.latency_csv" in str(refused.value) and str(missing) in str(refused.value)


def test_a_lognormal_latency_of_0_ms_is_refused_when_the_scenario_is_loaded():
    with pytest.raises(ConfigError) as refused:
        _load(**{"network.latency_model": "lognormal"})
    message = str(refused.value)
    assert "[network] latency_ms = 0.0: expected a value > 0 with latency_model 'lognormal'" in (
        message
    )
    ok = _load(**{"network.latency_model": "lognormal", "network.latency_ms": 2.0})
    assert ok.network.latency_model == "lognormal"


def test_an_empirical_model_without_a_file_is_refused_naming_latency_csv():
    with pytest.raises(ConfigError, match=r"latency_csv = '': expected a CSV file of delays"):
        _load(**{"network.latency_model": "empirical"})


@pytest.mark.parametrize("model", ["constant", "empirical"])
def test_jitter_is_refused_with_a_model_that_does_not_read_it(model, tmp_path: Path):
    csv = tmp_path / "d.csv"
    csv.write_text("1\n")
    extra = {"network.latency_csv": str(csv)} if model == "empirical" else {}
    with pytest.raises(ConfigError) as refused:
        _load(**{"network.latency_model": model, "network.jitter_ms": 2.0, **extra})
    assert (
        f"jitter_ms = 2.0: expected 0 with latency_model '{model}' "
        "(only 'lognormal' or 'normal' read jitter_ms)"
    ) in str(refused.value)


def test_a_latency_csv_is_refused_unless_the_model_is_empirical(tmp_path: Path):
    csv = tmp_path / "d.csv"
    csv.write_text("1\n")
    with pytest.raises(ConfigError, match="no latency_csv unless latency_model is 'empirical'"):
        _load(**{"network.latency_csv": str(csv)})
    loaded = _load(**{"network.latency_model": "empirical", "network.latency_csv": str(csv)})
    assert loaded.network.latency_csv == str(csv)


def test_only_the_models_that_read_a_key_declare_it():
    assert Normal.keys == Lognormal.keys == ("jitter_ms",)
    assert Empirical.keys == ("latency_csv",)
    assert not hasattr(Constant, "keys")

import numpy as np
import pytest

from models.errors import ModelError
from models.network.radio import PathLoss, free_space_loss_db


def test_the_default_reference_loss_is_free_space_at_1_m_on_5_ghz_channel_36():
    assert free_space_loss_db(1.0, 5.18e9) == pytest.approx(PathLoss().ref_loss_db, abs=0.05)
    assert free_space_loss_db(1.0, 2.4e9) == pytest.approx(40.0, abs=0.1)


def test_rssi_falls_10_n_db_per_decade_and_clamps_below_1_m():
    radio = PathLoss(tx_power_dbm=20.0, ref_loss_db=40.0, exponent=3.0)
    rssi = radio.rssi_dbm([0.1, 1.0, 10.0, 100.0])
    assert rssi.tolist() == pytest.approx([-20.0, -20.0, -50.0, -80.0])


def test_reception_probability_is_one_half_at_the_median_range_and_falls_with_distance():
    radio = PathLoss()
    median = radio.median_range_m()
    assert median == pytest.approx(10 ** ((20 - 46.7 + 82) / 30))
    assert radio.reception_probability(median) == pytest.approx(0.5)
    distances = np.array([1.0, 20.0, 50.0, median, 100.0, 200.0])
    p = radio.reception_probability(distances)
    assert np.all(np.diff(p) < 0)
    assert p[0] == pytest.approx(1.0) and p[-1] < 1e-3


def test_the_scalar_reception_probability_matches_the_vectorized_one():
    radio = PathLoss(shadowing_db=6.0)
    for d in [0.2, 1.0, 33.3, 70.0, 150.0]:
        assert radio.reception_probability_at(d) == pytest.approx(
            float(radio.reception_probability(d)), rel=1e-12, abs=1e-300
        )


def test_one_shadowing_deviation_closer_than_the_median_range_is_received_84_percent():
    radio = PathLoss(shadowing_db=4.0, exponent=2.0)
    # 4 dB at n = 2 is a distance factor 10**(4/20)
    d = radio.median_range_m() / 10 ** (4.0 / 20.0)
    assert radio.reception_probability_at(d) == pytest.approx(0.841345, abs=1e-6)


def test_without_shadowing_reception_is_a_step_at_the_median_range():
    radio = PathLoss(shadowing_db=0.0)
    median = radio.median_range_m()
    assert radio.reception_probability([median * 0.999, median * 1.001]).tolist() == [1.0, 0.0]
    assert radio.reception_probability_at(median * 1.001) == 0.0


@pytest.mark.parametrize(
    ("kwargs", "key"),
    [
        ({"exponent": 0.0}, "network.path_loss_exponent"),
        ({"shadowing_db": -1.0}, "network.shadowing_db"),
        ({"tx_power_dbm": float("nan")}, "network.tx_power_dbm"),
        ({"sensitivity_dbm": float("-inf")}, "network.sensitivity_dbm"),
    ],
)
def test_impossible_radio_parameters_are_refused(kwargs, key):
    with pytest.raises(ModelError) as error:
        PathLoss(**kwargs)
    assert error.value.key == key

import pytest

import cosim
from adapters.network.ns3.settings import Ns3Settings
from cosim.core.errors import ConfigError


def test_the_defaults_are_802_11g_at_6_mbit_and_free_space_at_2_4_ghz():
    cfg = Ns3Settings()
    assert (cfg.standard, cfg.rate, cfg.tx_power_dbm) == ("80211g", "ErpOfdmRate6Mbps", 20.0)
    assert cfg.reference_loss_db == pytest.approx(40.05, abs=0.01)
    assert cfg.base_xy_m == "middle"


@pytest.mark.parametrize(
    ("key", "value", "said"),
    [
        ("ns3.standard", '"80211z"', "80211z"),
        ("ns3.window_ms", "0", "window_ms"),
        ("ns3.fading", '"rayleigh"', "rayleigh"),
        ("ns3.wall_loss_db", "-1", "wall_loss_db"),
        ("ns3.base_xy_m", '"centre"', "base_xy_m"),
    ],
)
def test_a_bad_radio_key_is_refused_naming_it(key, value, said):
    import tomllib

    parsed = tomllib.loads(f"x = {value}")["x"]
    with pytest.raises(ConfigError, match=said):
        cosim.load_scenario("warehouse-random", {key: parsed})

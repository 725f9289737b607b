import pytest

import cosim
from cosim.core.errors import ConfigError


@pytest.mark.parametrize(
    ("overrides", "expected"),
    [
        ({"agents.reward_weights": [1.0, 2.0]}, r"reward_weights.*4 weights, one for each"),
        ({"agents.share_hz": 1e-9}, r"share_hz.*0 \(never\) or >= 0.001"),
        ({"agents.observe": ["goal", "goal"]}, r"observe.*each part named once"),
        ({"agents.observe": []}, r"observe.*at least one observation part"),
        ({"agents.observe": ["sonar"]}, r"sonar"),
        ({"agents.action": "jump"}, r"jump"),
        ({"agents.rewards": ["time", "time"], "agents.reward_weights": [1, 1]}, r"each term"),
        ({"agents.wake_on": ["alarm"]}, r"alarm"),
        ({"agents.lidar_bins": 0}, r"lidar_bins"),
    ],
)
def test_bad_agents_settings_are_refused_naming_key_and_expectation(overrides, expected):
    with pytest.raises(ConfigError, match=expected) as caught:
        cosim.load_scenario("lab-room", overrides)
    assert "[agents]" in str(caught.value) or "agents." in str(caught.value)


def test_without_weights_each_term_weighs_its_own_default():
    from cosim.envs import Agents

    section = cosim.load_scenario("lab-room").agents
    assert section.reward_weights == ()
    parts = Agents("lab-room", duration_s=1.0).episode.parts
    assert [t.name for t in parts.rewards] == ["progress", "arrived", "time", "contact"]
    assert parts.weights.tolist() == [1.0, 10.0, -0.1, -5.0]

"""Every topic an adapter publishes is advertised first (what bags and the live view rely on)."""

import pytest

import cosim
from cosim.core.bus import Bus
from cosim.runner.execute import execute
from tests.conftest import SMALL

DRIVERS = [
    {"robots.driver": "tasks", "assignment.protocol": protocol}
    for protocol in ("distributed_simplex", "cbba", "hungarian", "greedy")
] + [
    {"robots.driver": "navigation", "navigation.robots_layer": True},
    {"robots.driver": "waypoints"},
    {"robots.driver": "wander"},
]


@pytest.mark.parametrize("driver", DRIVERS, ids=lambda d: "-".join(map(str, d.values())))
def test_every_published_topic_was_advertised_with_the_type_published(
    driver, monkeypatch, tmp_path
):
    published: dict[str, set[type]] = {}
    advertised: dict[str, type] = {}
    original = Bus.publish

    def publish(self, topic, message, src):
        published.setdefault(topic, set()).add(type(message))
        advertised.update({t: ad.message_type for t, ad in self.advertised().items()})
        original(self, topic, message, src)

    monkeypatch.setattr(Bus, "publish", publish)
    overrides = {**SMALL, **driver, "scenario.duration_s": 8.0, "tasks.dwell_s": 0.5}
    execute(cosim.load_scenario("warehouse-random", overrides=overrides), out=tmp_path)
    assert published
    for topic, kinds in published.items():
        assert topic in advertised, topic
        assert kinds == {advertised[topic]}, topic

"""The network's pluggable parts: their groups, their contract checks, and the network view."""

from __future__ import annotations

from typing import Any, ClassVar

import pytest

from adapters.network.contract import (
    LATENCY_MODELS,
    LOSS_MODELS,
    NETWORK_BACKENDS,
    TOPOLOGIES,
    NetworkView,
)
from adapters.network.links import LinksBackend
from cosim.core.errors import RegistryError
from cosim.core.link import AllDelivered
from cosim.core.registry import Group, installed_groups
from models.network.topology import Edges, edge


class _Backend:
    """Every method of the contract; links as given."""

    name: ClassVar[str] = "fake"
    tables: ClassVar[tuple[Any, ...]] = ()

    def __init__(self, context: Any = None, links: Edges = frozenset()) -> None:
        self.links = links
        self.asked: list[int] = []

    def transmit(self, t_ns, src, dsts, nbytes, topic):
        return AllDelivered(t_ns)

    def start(self, run):
        pass

    def links_at(self, t_ns: int) -> Edges:
        self.asked.append(t_ns)
        return self.links

    def robot_graph(self):
        return ["robot_1", "robot_2", "robot_3"], frozenset({edge("robot_1", "robot_2")})

    def finish(self, run):
        return {}


class _NoFinish:
    name: ClassVar[str] = "nofinish"

    def transmit(self, t_ns, src, dsts, nbytes, topic):
        return AllDelivered(t_ns)

    def start(self, run):
        pass

    def links_at(self, t_ns):
        return frozenset()

    def robot_graph(self):
        return [], frozenset()


GROUPS = [NETWORK_BACKENDS, LATENCY_MODELS, LOSS_MODELS, TOPOLOGIES]


@pytest.mark.parametrize(
    ("group", "names"),
    [
        (NETWORK_BACKENDS, ["links"]),
        (LATENCY_MODELS, ["constant", "normal", "lognormal", "empirical"]),
        (LOSS_MODELS, ["none", "bernoulli", "gilbert_elliott"]),
        (TOPOLOGIES, ["complete", "range", "binomial", "ring", "explicit"]),
    ],
)
def test_every_built_in_choice_is_registered_and_passes_its_contract(group: Group, names):
    loaded = group.installed().load_all()
    assert set(names) <= set(loaded)
    for name in names:
        assert isinstance(loaded[name], type) and loaded[name].name == name


def test_the_four_groups_are_registered_for_the_references_and_cosim_plugins():
    registered = {g.entry_points: g for g in installed_groups()}
    for group in GROUPS:
        assert registered[group.entry_points] is group
    assert [g.chosen_by for g in GROUPS] == [
        "`network.backend`",
        "`network.latency_model`",
        "`network.loss_model`",
        "`network.topology`",
    ]


def test_the_built_in_backend_is_the_links_model():
    assert NETWORK_BACKENDS.installed().get("links") is LinksBackend


def test_a_backend_that_is_not_a_class_is_refused_naming_it():
    registry = NETWORK_BACKENDS.installed().with_entry("fake", _Backend())
    with pytest.raises(RegistryError, match=r"network backend 'fake' .*is not a class"):
        registry.get("fake")


def test_a_backend_without_a_method_of_the_contract_is_refused_naming_the_method():
    registry = NETWORK_BACKENDS.installed().with_entry("nofinish", _NoFinish)
    with pytest.raises(RegistryError) as refused:
        registry.get("nofinish")
    message = str(refused.value)
    assert "network backend 'nofinish'" in message
    assert "has no finish() method" in message and "NetworkBackend" in message


def test_a_backend_with_every_method_is_accepted():
    assert NETWORK_BACKENDS.installed().with_entry("fake", _Backend).get("fake") is _Backend


@pytest.mark.parametrize("group", [LATENCY_MODELS, LOSS_MODELS, TOPOLOGIES])
def test_a_choice_of_the_links_backend_that_is_not_a_class_is_refused(group: Group):
    def model(context: Any) -> None:
        return None

    model.name = "func"  # type: ignore[attr-defined]
    registry = group.installed().with_entry("func", model)
    with pytest.raises(RegistryError, match=rf"{group.words} 'func' .*is not a class"):
        registry.get("func")
    assert "func" not in registry.load_all()  # broken entries are left out


def test_the_view_answers_who_hears_whom_from_the_backend_at_that_time():
    links = frozenset(
        {edge("base", "robot_1"), edge("robot_1", "robot_2"), edge("base", "robot_3")}
    )
    backend = _Backend(links=links)
    view = NetworkView(backend)
    assert view.up_links(5) == links
    assert view.neighbors("robot_1", 7) == ["base", "robot_2"]
    assert view.neighbors("base", 8) == ["robot_1", "robot_3"]
    assert view.neighbors("robot_4", 9) == []
    assert backend.asked == [5, 7, 8, 9]


def test_the_view_gives_the_backends_robot_graph():
    robots, edges = NetworkView(_Backend()).robot_graph()
    assert robots == ["robot_1", "robot_2", "robot_3"]
    assert edges == frozenset({("robot_1", "robot_2")})

"""The network adapter: builds the backend network.backend names, installs it on the bus."""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from typing import Any, ClassVar

import pytest

import adapters.network.network as network
import cosim
from adapters.network.contract import NETWORK_BACKENDS, NetworkContext, NetworkView
from adapters.network.links import LinksBackend
from adapters.network.network import NetworkAdapter
from adapters.network.settings import NetworkConfig
from cosim.core.adapter import RunContext
from cosim.core.bus import Envelope
from cosim.core.errors import RegistryError
from cosim.core.hosts import BASE_HOST, HostId
from cosim.core.link import DELIVERED, Transfer
from cosim.core.messages import Clock, Message
from cosim.core.registry import Registry
from cosim.runner.assembly import assemble
from models.network.topology import complete, edge, ring
from tests.conftest import SMALL


class Radio:
    """A backend given in code: 2 ms to every host but robot_3, which it jams."""

    name: ClassVar[str] = "radio"
    tables: ClassVar[tuple[Any, ...]] = ()

    def __init__(self, context: NetworkContext) -> None:
        self.robots = list(context.robots)
        self.latency_ms = context.network.latency_ms
        self.sent: list[tuple[int, str, list[str], str]] = []
        self.started = False

    def transmit(
        self, t_ns: int, src: HostId, dsts: Sequence[HostId], nbytes: int, topic: str
    ) -> list[Transfer]:
        self.sent.append((t_ns, src, list(dsts), topic))
        return [
            Transfer(d, "jammed", None)
            if d == "robot_3"
            else Transfer(d, DELIVERED, t_ns + 2_000_000)
            for d in dsts
        ]

    def start(self, run: RunContext) -> None:
        self.started = True

    def links_at(self, t_ns: int) -> frozenset[tuple[str, str]]:
        return frozenset({edge("base", "robot_1"), edge("robot_1", "robot_2")})

    def robot_graph(self) -> tuple[list[str], frozenset[tuple[str, str]]]:
        return self.robots, ring(self.robots)

    def finish(self, run: RunContext) -> dict[str, Any]:
        return {"radio_transmissions": len(self.sent)}


class _Installed:
    """Stands for the group in the adapter: its installed registry, with entries given in code."""

    def __init__(self, registry: Registry[Any]) -> None:
        self.registry = registry

    def installed(self) -> Registry[Any]:
        return self.registry


def _scenario(backend: str = "links", **network_keys: Any) -> cosim.Scenario:
    scenario = cosim.load_scenario("warehouse-random", SMALL)
    cfg = dataclasses.replace(scenario.section(NetworkConfig), backend=backend, **network_keys)
    return scenario.with_section("network", cfg)


def _with(monkeypatch: pytest.MonkeyPatch, name: str, backend: Any) -> None:
    registry = NETWORK_BACKENDS.installed().with_entry(name, backend)
    monkeypatch.setattr(network, "NETWORK_BACKENDS", _Installed(registry))


def _assembled(scenario: cosim.Scenario) -> tuple[RunContext, NetworkAdapter]:
    assembly = assemble(scenario, names=["world", "fleet", "network"])
    adapter = dict(assembly.adapters)["network"]
    assert isinstance(adapter, NetworkAdapter)
    return assembly.run, adapter


def test_the_built_in_links_backend_is_installed_by_default():
    run, adapter = _assembled(_scenario())
    assert isinstance(adapter.backend, LinksBackend)
    assert run.bus.link is adapter.backend
    robots, edges = run.service(NetworkView).robot_graph()
    assert robots == ["robot_1", "robot_2", "robot_3"] and edges == complete(robots)


def test_a_backend_given_in_code_replaces_the_built_in_one_on_the_bus(monkeypatch):
    _with(monkeypatch, "radio", Radio)
    run, adapter = _assembled(_scenario("radio", latency_ms=4.0))
    assert isinstance(adapter.backend, Radio)
    assert run.bus.link is adapter.backend
    # built with the run's context: the fleet's robots and the [network] section
    assert adapter.backend.robots == ["robot_1", "robot_2", "robot_3"]
    assert adapter.backend.latency_ms == 4.0


def test_the_network_view_answers_from_the_chosen_backend(monkeypatch):
    _with(monkeypatch, "radio", Radio)
    run, _ = _assembled(_scenario("radio"))
    view = run.service(NetworkView)
    assert view.neighbors("robot_1", 0) == ["base", "robot_2"]
    assert view.up_links(0) == {("base", "robot_1"), ("robot_1", "robot_2")}
    robots, edges = view.robot_graph()
    assert edges == ring(robots)


def test_every_message_between_hosts_takes_the_fate_the_backend_gives_it(monkeypatch):
    _with(monkeypatch, "radio", Radio)
    run, adapter = _assembled(_scenario("radio"))
    got: list[tuple[str, int]] = []

    def keep(host: str):
        def on(message: Message, envelope: Envelope) -> None:
            got.append((host, envelope.t_recv_ns))

        return on

    for host in ("robot_2", "robot_3"):
        run.bus.subscribe("/chatter", HostId(host), keep(host))
    adapter.start(run)
    run.kernel.at(1_000_000, lambda: run.bus.publish("/chatter", Clock(0), HostId("robot_1")))
    run.kernel.run(10_000_000)
    assert adapter.backend.sent == [(1_000_000, "robot_1", ["robot_2", "robot_3"], "/chatter")]
    assert got == [("robot_2", 3_000_000)]  # robot_3's copy was jammed


def test_the_backend_is_started_with_the_run_and_gives_the_summary(monkeypatch):
    _with(monkeypatch, "radio", Radio)
    run, adapter = _assembled(_scenario("radio"))
    assert not adapter.backend.started
    adapter.start(run)
    assert adapter.backend.started
    run.bus.publish("/chatter", Clock(0), BASE_HOST)  # nobody listens: nothing transmitted
    assert adapter.finish(run) == {"radio_transmissions": 0}


def test_a_backend_breaking_the_contract_is_refused_when_the_run_is_assembled(monkeypatch):
    class Mute:
        name: ClassVar[str] = "mute"

        def __init__(self, context: NetworkContext) -> None:
            pass

    _with(monkeypatch, "mute", Mute)
    with pytest.raises(RegistryError, match=r"network backend 'mute' .*has no transmit\(\)"):
        _assembled(_scenario("mute"))

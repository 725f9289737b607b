"""``cosim check-plugin``'s own checks: finding the entry, loads, contract, settings."""

from __future__ import annotations

from dataclasses import dataclass, field
from importlib.metadata import EntryPoint
from typing import ClassVar

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from adapters.assignment.contract import PROTOCOLS, ProtocolBase
from adapters.navigation.contract import CONTROLLERS
from cosim.core.errors import RegistryError
from cosim.core.registry import Lazy, Registry, registered
from cosim.scenario.fields import Problem, param
from cosim.scenario.model import SECTIONS
from cosim.testing.checks import (
    Target,
    check_contract,
    check_loads,
    check_plugin,
    check_settings,
    find_entry,
    plugin_words,
    section_problems,
)


@pytest.mark.parametrize("text", ["cbba", "cosim.protocols:cbba", "protocols:cbba",
                                  "protocol:cbba"])  # fmt: skip
def test_an_entry_is_found_by_its_name_or_its_group_and_name(text):
    target = find_entry(text)
    assert (target.group, target.name) == (PROTOCOLS, "cbba")
    assert target.describe() == (
        "assignment protocol 'cbba' (adapters.assignment.protocols:Cbba, package cosim)"
    )


def test_a_name_several_groups_hold_is_refused_naming_them_and_how_to_choose():
    with pytest.raises(RegistryError) as refused:
        find_entry("navigation")
    assert str(refused.value) == (
        "'navigation' is registered in cosim.adapters, cosim.drivers, cosim.sections: name one "
        "as GROUP:NAME (e.g. cosim.adapters:navigation)"
    )
    assert find_entry("drivers:navigation").group.entry_points == "cosim.drivers"


def test_a_name_held_by_a_plugin_and_its_settings_section_is_the_plugin():
    assert find_entry("network").group.entry_points == "cosim.adapters"
    assert find_entry("sections:network").group == SECTIONS


def test_an_unknown_name_or_group_is_refused_with_the_nearest_ones():
    with pytest.raises(RegistryError, match=r"^no plugin 'greedyy' in any registry; did you "
                       r"mean 'greedy'\?"):  # fmt: skip
        find_entry("greedyy")
    with pytest.raises(RegistryError, match=r"^'protocls:cbba': no registry 'protocls'; did you "
                       r"mean 'protocols'\?"):  # fmt: skip
        find_entry("protocls:cbba")
    with pytest.raises(RegistryError, match="no plugin 'dwa' in any registry"):
        find_entry("planners:dwa")


@settings(max_examples=40, deadline=None)
@given(
    st.one_of(
        st.text(alphabet=st.characters(blacklist_categories=["Cs"]), min_size=1, max_size=30),
        st.builds("{}:{}".format, st.sampled_from(["protocols", "x", "cosim.drivers"]), st.text()),
    )
)
def test_any_text_is_found_or_refused_in_one_line_naming_it(text):
    try:
        target = find_entry(text)
    except RegistryError as error:
        said = str(error)
        assert "\n" not in said
        assert repr(text) in said or repr(text.rpartition(":")[2]) in said
    else:
        assert target.name == text.rpartition(":")[2]


def broken_registry(value: str) -> Target:
    point = EntryPoint(name="broken", value=value, group="cosim.protocols")
    return Target(PROTOCOLS, "broken", Registry(PROTOCOLS, {"broken": Lazy(point)}))


def test_an_entry_whose_module_does_not_import_fails_loads_and_nothing_else_is_tried():
    target = broken_registry("labkit_gone.auction:Auction")
    outcomes = list(check_plugin(target))
    assert [o.line() for o in outcomes] == [
        "FAIL loads: labkit_gone.auction:Auction cannot be imported: ModuleNotFoundError: "
        "No module named 'labkit_gone'"
    ]
    missing = check_loads(broken_registry("adapters.assignment.protocols:Auctioneer"))
    assert missing.line().endswith(
        "AttributeError: module 'adapters.assignment.protocols' has no attribute 'Auctioneer'"
    )


class Unnamed(ProtocolBase):
    """Declares another name than the one it is registered under."""

    name: ClassVar[str] = "something_else"


class NoOrders:
    """Lacks what every protocol has."""

    name: ClassVar[str] = "no_orders"
    message = None
    topic = None
    central = False
    compare_to_optimum = False

    def agent(self) -> None: ...

    def summary(self) -> None: ...


def test_the_contract_check_is_the_groups_and_the_declared_name_must_match():
    with registered("cosim.protocols", "unnamed", Unnamed):
        outcome = check_contract(find_entry("unnamed"))
    assert outcome.failed and outcome.detail.endswith(
        "declares name = 'something_else'; expected 'unnamed'"
    )
    with registered("cosim.protocols", "no_orders", NoOrders):
        outcome = check_contract(find_entry("no_orders"))
    assert outcome.failed and outcome.detail.endswith(
        "has no orders() method (see adapters.assignment.contract)"
    )
    assert check_contract(find_entry("dwa")).line() == (
        "ok   contract: follows adapters.navigation.contract (LocalController)"
    )


def test_an_adapter_requiring_an_unregistered_one_fails_its_contract():
    class Needy:
        name = "needy"
        requires = ("fleet", "sonar")

        def __init__(self, run: object) -> None: ...

        def start(self, run: object) -> None: ...

        def finish(self, run: object) -> dict[str, int]:
            return {}

    with registered("cosim.adapters", "needy", Needy):
        outcome = check_contract(find_entry("needy"))
    assert outcome.failed and "requires unknown adapter 'sonar'" in outcome.detail


@dataclass(frozen=True)
class Sloppy:
    """``[sloppy]``: keys that break the naming rules."""

    cruise: float = param(0.8, "speed on a straight path (m/s)", gt=0)
    reach_s: float = param(4.0, "how far it looks (m)", gt=0)
    rate_hz: float = param(10.0, "ticks per second (Hz)", gt=0)
    label: str = field(default="x")
    count: int = param(0, "how many (an integer >= 1)")

    def problems(self) -> list[Problem]:
        return [Problem("count", self.count, "an integer >= 1")] if self.count < 1 else []


def test_a_section_names_every_key_without_doc_without_its_unit_and_defaults_it_refuses():
    assert section_problems(Sloppy) == [
        "key 'cruise' is in m/s (its doc says) but its name carries no unit: cruise_mps",
        "key 'reach_s' is in m (its doc says) but its name carries s: reach_m",
        "key 'label' has no one-line doc: declare it with param(default, doc)",
        "its defaults are refused: count = 0: an integer >= 1",
    ]
    assert section_problems(SECTIONS.installed().get("network")) == []


def test_the_settings_check_reads_the_section_of_the_entrys_name_or_the_section_itself():
    with registered("cosim.sections", "sloppy", Sloppy):
        outcome = check_settings(find_entry("sloppy"))
    assert outcome.failed and outcome.detail.startswith(
        "[sloppy] key 'cruise' is in m/s (its doc says)"
    )
    assert (
        check_settings(find_entry("adapters:navigation"))
        .line()
        .startswith("ok   settings: [navigation] 17 keys: builds from its defaults")
    )
    assert check_settings(find_entry("dwa")).line() == (
        "skip settings: no [dwa] section registered in cosim.sections"
    )


def test_the_plugins_words_name_its_package_and_version():
    target = Target(CONTROLLERS, "dwa", CONTROLLERS.installed())
    assert plugin_words(target).startswith(
        "local controller 'dwa' (adapters.navigation.local_control:DwaControl, cosim "
    )

"""The installed entry points, read once: cosim's first, and names two packages both claim."""

from __future__ import annotations

from pathlib import Path

import pytest

from cosim.core.entrypoints import claims, clashes, entries, installed, registered_once
from cosim.core.errors import RegistryError
from tests.packages import on_path, write_package

SHARED = {"cosim.controllers": {"shared": "alphakit.a:A"}}


def test_a_name_two_plugin_packages_register_stops_the_group_naming_both_and_their_targets(
    tmp_path: Path,
):
    write_package(tmp_path, "betakit", "2.0", {"cosim.controllers": {"shared": "betakit.b:B"}})
    write_package(tmp_path, "alphakit", "1.0", SHARED)
    with on_path(tmp_path):
        with pytest.raises(RegistryError) as refused:
            entries("cosim.controllers")
        assert str(refused.value) == (
            "cosim.controllers: 'shared' is registered by alphakit 1.0 (alphakit.a:A) and by "
            "betakit 2.0 (betakit.b:B); uninstall one or rename it"
        )
        assert "shared" not in registered_once("cosim.controllers")
        assert "dwa" in registered_once("cosim.controllers")
        assert "hungarian" in entries("cosim.protocols")  # other groups load


def test_a_plugin_taking_a_builtin_name_clashes_with_cosim_named_first(tmp_path: Path):
    greedy = {"cosim.protocols": {"greedy": "clashkit.greedy:Greedy"}}
    write_package(tmp_path, "clashkit", "0.1.0", greedy)
    with on_path(tmp_path):
        [clash] = clashes("cosim.protocols")
        assert str(clash) == (
            "cosim.protocols: 'greedy' is registered by cosim "
            "(adapters.assignment.protocols:Greedy) and by clashkit 0.1.0 "
            "(clashkit.greedy:Greedy); uninstall one or rename it"
        )
        assert [c.package for c in claims("cosim.protocols")["greedy"]] == ["cosim", "clashkit"]


def test_three_claimants_and_further_clashes_are_said_in_one_line(tmp_path: Path):
    write_package(
        tmp_path, "akit", "1", {"cosim.controllers": {"shared": "akit.m:X", "o": "akit.m:Y"}}
    )
    write_package(
        tmp_path, "bkit", "1", {"cosim.controllers": {"shared": "bkit.m:X", "o": "bkit.m:Y"}}
    )
    write_package(tmp_path, "ckit", "1", {"cosim.controllers": {"shared": "ckit.m:X"}})
    with on_path(tmp_path), pytest.raises(RegistryError) as refused:
        entries("cosim.controllers")
    message = str(refused.value)
    assert "\n" not in message
    assert "'shared' is registered by akit 1 (akit.m:X), by bkit 1 (bkit.m:X) and by ckit 1" in (
        message
    )
    assert message.endswith("(1 more there: `cosim plugins` lists them)")


def test_a_distribution_found_twice_on_the_path_counts_once_and_clashes_with_nothing(
    tmp_path: Path,
):
    write_package(tmp_path / "one", "alphakit", "1.0", SHARED)
    write_package(tmp_path / "two", "alphakit", "1.0", SHARED)
    with on_path(tmp_path / "one"), on_path(tmp_path / "two"):
        assert entries("cosim.controllers")["shared"].value == "alphakit.a:A"
        assert clashes("cosim.controllers") == []


def test_entries_come_cosims_first_then_other_packages_by_name(tmp_path: Path):
    write_package(tmp_path, "zkit", "1", {"cosim.planners": {"zz": "zkit.p:P"}})
    write_package(tmp_path, "Akit", "1", {"cosim.planners": {"aa": "akit.p:P"}})
    with on_path(tmp_path):
        packages = [p.package for p in installed() if p.group == "cosim.planners"]
        assert packages == ["cosim", "cosim", "cosim", "Akit", "zkit"]
        assert list(entries("cosim.planners")) == [
            "astar", "hybrid_astar", "thetastar", "aa", "zz"
        ]  # fmt: skip
        assert entries("cosim.planners")["aa"].owner() == "Akit 1"
        assert entries("cosim.planners")["astar"].owner() == "cosim"

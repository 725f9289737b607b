"""Sections a resolved scenario gained or lost (cosim.studies.gained): which change the runs."""

from __future__ import annotations

from pathlib import Path

import pytest

import cosim
from cosim.scenario.loader import dump_scenario
from cosim.studies.gained import (
    changes_runs,
    dump_of,
    gained,
    gained_line,
    owner,
    refuse_gained,
    refuse_lost,
    section_owners,
    toml_sections,
)
from tests.packages import on_path, write_package

SETTINGS = '''"""A plugin's settings section."""

from dataclasses import dataclass

from cosim.scenario.fields import param


@dataclass(frozen=True)
class Settings:
    """[{name}]: a gain, and an adapter it may start."""

    gain: float = param(1.0, "a gain", gt=0)
    enabled: bool = param({enabled}, "start the {name} adapter")
{more}
    def adapters(self):
        """The adapter these settings ask for."""
        return ("{name}",) if self.enabled else ()


class Adapter:
    """Starts and finishes, and reads its settings."""

    name = "{name}"
    requires = ("fleet",)

    def __init__(self, run):
        self.gain = run.settings(Settings).gain

    def start(self, run):
        pass

    def finish(self, run):
        return {{"{name}_gain": self.gain}}
'''

CLAIMS = '''
    def claim_rules(self):
        """How the task book is kept: a hook every run asks of every section."""
        return None
'''


def install(site: Path, name: str, *, enabled: bool = False, more: str = "") -> Path:
    """A package ``name`` 0.1.0 registering section [name] and its adapter (:data:`SETTINGS`)."""
    source = SETTINGS.format(name=name, enabled=enabled, more=more)
    entry = {
        "cosim.sections": {name: f"{name}.settings:Settings"},
        "cosim.adapters": {name: f"{name}.settings:Adapter"},
    }
    return write_package(site, name, "0.1.0", entry, {f"{name}/settings.py": source})


def test_a_section_no_run_sets_and_whose_defaults_start_nothing_changes_no_run(tmp_path):
    with on_path(install(tmp_path, "quietkit")):
        scenario = cosim.load_scenario("warehouse-random")
        assert "quietkit" in scenario.sections
        assert changes_runs(scenario, "quietkit") == ""
        assert owner("quietkit") == "quietkit 0.1.0"
        assert section_owners(scenario)["quietkit"] == "quietkit 0.1.0"
        assert section_owners(scenario)["world"].startswith("cosim ")


@pytest.mark.parametrize(
    ("enabled", "more", "overrides", "why"),
    [
        (True, "", {}, "its defaults start adapter 'kit' in every run"),
        (False, "", {"kit.gain": 2.0}, "[kit] gain = 2.0, not its default"),
        (False, CLAIMS, {}, "it declares claim_rules(), which a run may ask of every section"),
    ],
)
def test_a_section_that_starts_an_adapter_is_set_or_hooks_into_runs_changes_them(
    tmp_path, enabled, more, overrides, why
):
    with on_path(install(tmp_path, "kit", enabled=enabled, more=more)):
        scenario = cosim.load_scenario("warehouse-random", overrides)
        assert changes_runs(scenario, "kit") == why


def test_gained_names_the_new_sections_their_packages_and_the_first_that_changes_a_run(tmp_path):
    then = list(cosim.load_scenario("warehouse-random").sections)
    install(tmp_path, "quietkit")
    with on_path(install(tmp_path, "loudkit", enabled=True)):
        scenario = cosim.load_scenario("warehouse-random")
        found = gained([("runs 0000_s*", scenario)], then, section_owners(scenario))
    assert found.sections == ("loudkit", "quietkit")
    assert found.named() == "[loudkit] (package loudkit 0.1.0), [quietkit] (package quietkit 0.1.0)"
    assert found.why == "its defaults start adapter 'loudkit' in every run"
    line = str(refuse_gained(found, "study.toml", "out", 3))
    assert line == (
        "study.toml: the resolved scenario gained [loudkit] (package loudkit 0.1.0), "
        "[quietkit] (package quietkit 0.1.0) since out was started, and it changes the runs "
        "(its defaults start adapter 'loudkit' in every run); resuming would mix runs with and "
        "without it in one table: uninstall loudkit, quietkit to resume, or run this study "
        "with another --out (the 3 finished runs in out stay there)"
    )


def test_a_key_set_in_one_combination_is_named_with_that_combination(tmp_path):
    then = list(cosim.load_scenario("warehouse-random").sections)
    with on_path(install(tmp_path, "quietkit")):
        plain = cosim.load_scenario("warehouse-random")
        tuned = cosim.load_scenario("warehouse-random", {"quietkit.gain": 3.0})
        found = gained([("runs 0000_s*", plain), ("runs 0001_s*", tuned)], then, {})
    assert found.why == "[quietkit] gain = 3.0, not its default in runs 0001_s*"


def test_the_note_of_a_resume_says_which_section_and_package_and_why_the_runs_stand(tmp_path):
    then = list(cosim.load_scenario("warehouse-random").sections)
    with on_path(install(tmp_path, "quietkit")):
        scenario = cosim.load_scenario("warehouse-random")
        found = gained([("runs 0000_s*", scenario)], then, section_owners(scenario))
    assert not found.why
    assert gained_line(found, "runs/studies/x", 4) == (
        "runs/studies/x: the resolved scenario gained [quietkit] (package quietkit 0.1.0) "
        "since the folder was started (a package installed since); no run of this study sets "
        "its keys and its defaults start nothing, so the 4 finished runs stand: resuming"
    )


def test_a_section_gone_names_its_package_and_how_to_resume():
    line = str(refuse_lost(["quietkit"], {"quietkit": "quietkit 0.1.0"}, "s.toml", "out", 2))
    assert line == (
        "s.toml: [quietkit] (package quietkit 0.1.0) is gone from the resolved scenario since "
        "out was started (its package uninstalled, or failing to load: `cosim plugins` says); "
        "the finished runs had it: install quietkit again to resume, or run this study with "
        "another --out (the 2 finished runs in out stay there)"
    )


def test_the_scenario_as_it_was_then_is_its_dump_without_the_new_sections(tmp_path):
    before = dump_scenario(cosim.load_scenario("warehouse-random"))
    then = toml_sections(before)
    assert then is not None and "provenance" not in then and then[0] == "scenario"
    with on_path(install(tmp_path, "quietkit")):
        now = cosim.load_scenario("warehouse-random")
        assert "[quietkit]" in dump_scenario(now)
        assert dump_of(now, then) == before


@pytest.mark.parametrize("text", ["[x", "a = 1\n", "[[a]]\nb = 1\n"])
def test_a_garbled_or_sectionless_file_has_no_sections_to_compare(text):
    assert not toml_sections(text)

"""What a run used: cosim and every entry it chose, by package and version, in its folder."""

from __future__ import annotations

import json
import tomllib
from importlib.metadata import version
from pathlib import Path

import cosim
from cosim.runner.provenance import packages
from tests.conftest import cosim_main
from tests.packages import on_path, write_package

PROBE = '''"""An adapter of a plugin package."""


class Probe:
    """Starts and finishes."""

    name = "probe"
    requires = ("fleet",)

    def __init__(self, run):
        pass

    def start(self, run):
        pass

    def finish(self, run):
        return {}
'''


class GivenProbe:
    """An adapter handed to cosim.run in code."""

    name = "given_probe"
    requires = ()

    def __init__(self, run):
        pass

    def start(self, run):
        pass

    def finish(self, run):
        return {}


def _probekit(site: Path, release: str) -> Path:
    adapters = {"cosim.adapters": {"probe": "probekit.probe:Probe"}}
    return write_package(site, "probekit", release, adapters, {"probekit/probe.py": PROBE})


def _key(entry: dict[str, str]) -> tuple[str, str]:
    return entry["group"], entry["name"]


def test_the_summary_names_cosim_then_every_adapter_section_and_choice_with_its_version(
    small_scenario,
):
    result = cosim.run(small_scenario, duration_s=0.2)
    plugins = result.summary["plugins"]
    cosim_version = version("cosim")
    assert plugins[0] == {
        "package": "cosim",
        "version": cosim_version,
        "group": "",
        "name": "",
        "target": "",
    }
    listed = {_key(p): p for p in plugins[1:]}
    for adapter in ("world", "fleet", "lidar", "waypoints", "poses"):
        assert ("cosim.adapters", adapter) in listed
    for section in small_scenario.sections:
        assert ("cosim.sections", section) in listed
    assert listed["cosim.drivers", "waypoints"]["target"] == "adapters.drivers.stacks:WAYPOINTS"
    assert listed["cosim.controllers", "dwa"]["version"] == cosim_version
    assert ("cosim.loss_models", "none") in listed and ("cosim.topologies", "complete") in listed
    assert not any(group == "cosim.mocap_sources" for group, _ in listed)  # source "none"
    assert {p["package"] for p in plugins} == {"cosim"}
    assert len(listed) == len(plugins) - 1  # each entry once


def test_an_adapter_given_in_code_is_listed_without_a_package_and_left_out_of_packages(
    small_scenario,
):
    result = cosim.run(small_scenario, duration_s=0.2, adapters=[GivenProbe])
    [given] = [p for p in result.summary["plugins"] if p["name"] == "given_probe"]
    assert given == {
        "package": "",
        "version": "",
        "group": "cosim.adapters",
        "name": "given_probe",
        "target": f"{__name__}:GivenProbe",
    }
    assert packages(result.summary["plugins"]) == {"cosim": version("cosim")}


def test_a_plugins_version_reaches_the_run_folder_and_a_later_version_is_noted(tmp_path):
    out = tmp_path / "run"
    with on_path(_probekit(tmp_path / "site", "0.2.0")):
        scenario = cosim.load_scenario(
            "warehouse-random",
            {"scenario.duration_s": 0.2, "robots.count": 2, "scenario.adapters": ["probe"]},
        )
        cosim.run(scenario, out=out)
    summary = json.loads((out / "summary.json").read_text())
    [probe] = [p for p in summary["plugins"] if _key(p) == ("cosim.adapters", "probe")]
    assert (probe["package"], probe["version"]) == ("probekit", "0.2.0")
    resolved = tomllib.loads((out / "scenario.toml").read_text())
    assert resolved["provenance"] == {"cosim": version("cosim"), "probekit": "0.2.0"}

    with on_path(_probekit(tmp_path / "newer", "0.3.0")):
        checked = cosim_main("check", str(out / "scenario.toml"))
        printed = cosim_main("check", str(out / "scenario.toml"), "--print")
    assert checked.returncode == 0, checked.stderr
    assert checked.stderr == (
        f"note: {out / 'scenario.toml'} was resolved with probekit 0.2.0; installed: probekit "
        "0.3.0 (results may differ from that run's)\n"
    )
    assert "[scenario]" in printed.stdout and "[provenance]" not in printed.stdout

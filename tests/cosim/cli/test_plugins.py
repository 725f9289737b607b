"""`cosim plugins`, and plugins that are broken: named when used, harmless when not."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from tests.conftest import REPO, cosim_main
from tests.packages import env_with, on_path, write_package

BROKEN_ENTRY_POINTS = """[cosim.protocols]
broken_auction = brokenplug.missing:Auction

[cosim.sections]
broken_auction = brokenplug.missing:Settings

[cosim.adapters]
lazy_sensor = brokenplug.sensor:NoFinish
"""
SENSOR = '''"""An adapter that forgot its finish() method."""


class NoFinish:
    """Starts, never finishes."""

    name = "lazy_sensor"
    requires = ("fleet",)

    def __init__(self, run):
        pass

    def start(self, run):
        pass
'''


@pytest.fixture(scope="module")
def broken(tmp_path_factory: pytest.TempPathFactory) -> dict[str, str]:
    """An environment with a package whose plugins are broken (as if pip-installed)."""
    site = tmp_path_factory.mktemp("site")
    info = site / "brokenplug-0.1.dist-info"
    info.mkdir()
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: brokenplug\nVersion: 0.1\n")
    (info / "entry_points.txt").write_text(BROKEN_ENTRY_POINTS)
    (site / "brokenplug").mkdir()
    (site / "brokenplug" / "__init__.py").write_text("")
    (site / "brokenplug" / "sensor.py").write_text(SENSOR)
    return {**os.environ, "PYTHONPATH": os.pathsep.join([str(site), str(REPO)])}


def cosim(env: dict[str, str], *args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "cosim", *args], capture_output=True, text=True, env=env, timeout=120
    )


def test_plugins_lists_every_registry_with_its_package_and_a_line_of_description():
    done = cosim_main("plugins")
    assert done.returncode == 0, done.stderr
    for heading in (
        "adapters (cosim.adapters)",
        "settings sections (cosim.sections)",
        "robot drivers (cosim.drivers)",
        "assignment protocols (cosim.protocols)",
        "local controllers (cosim.controllers)",
        "global planners (cosim.planners)",
        "traffic policies (cosim.traffic)",
    ):
        assert heading in done.stdout
    line = next(li for li in done.stdout.splitlines() if li.split()[:2] == ["hungarian", "cosim"])
    assert "Hungarian" in line


def test_plugins_can_list_one_registry_and_refuses_an_unknown_one():
    assert cosim_main("plugins", "planner").stdout.splitlines()[0].startswith("global planners")
    assert cosim_main("plugins", "cosim.protocols").stdout.startswith("assignment protocols")
    done = cosim_main("plugins", "protokols")
    assert done.returncode == 2 and "'protokols' is not a registry" in done.stderr


@pytest.mark.slow
def test_a_broken_plugin_stops_no_run_that_does_not_use_it(broken, tmp_path):
    done = cosim(
        broken, "run", "warehouse-random", "--duration-s", "2", "--out", str(tmp_path / "r")
    )
    assert done.returncode == 0, done.stderr
    assert "broken_auction" not in (tmp_path / "r" / "scenario.toml").read_text()


@pytest.mark.slow
def test_cosim_plugins_lists_a_broken_plugin_with_its_package_and_why(broken):
    done = cosim(broken, "plugins", "protocol", "adapter")
    assert done.returncode == 0, done.stderr
    line = next(li for li in done.stdout.splitlines() if li.strip().startswith("broken_auction"))
    assert "brokenplug" in line and "BROKEN" in line and "ModuleNotFoundError" in line
    line = next(li for li in done.stdout.splitlines() if li.strip().startswith("lazy_sensor"))
    assert "has no finish(run) method" in line


@pytest.mark.slow
@pytest.mark.parametrize(
    ("setting", "fragment"),
    [
        (
            "assignment.protocol=broken_auction",
            "assignment protocol 'broken_auction' (brokenplug.missing:Auction, package "
            "brokenplug) cannot be loaded: ModuleNotFoundError",
        ),
        (
            "broken_auction.rounds=3",
            "settings section 'broken_auction' (brokenplug.missing:Settings, package "
            "brokenplug) cannot be loaded",
        ),
        (
            'scenario.adapters=["lazy_sensor"]',
            "adapter 'lazy_sensor' (brokenplug.sensor:NoFinish, package brokenplug): has no "
            "finish(run) method",
        ),
    ],
)
def test_a_run_that_uses_a_broken_plugin_is_refused_in_one_line_naming_it(
    broken, tmp_path: Path, setting: str, fragment: str
):
    args = ["run", "warehouse-random", "--set", "robots.driver=tasks", "--set", setting]
    done = cosim(broken, *args, "--out", str(tmp_path / "r"))
    assert done.returncode == 2, done.stderr
    assert fragment in done.stderr
    assert done.stderr.count("\n") == 1 and "Traceback" not in done.stderr
    assert not (tmp_path / "r").exists()


GREEDY = '"""A greedy of its own."""\n\n\nclass Greedy:\n    """Mine."""\n\n    name = "greedy"\n'
CLASH = (
    "cosim.protocols: 'greedy' is registered by cosim (adapters.assignment.protocols:Greedy) "
    "and by clashkit 0.1.0 (clashkit.greedy:Greedy); uninstall one or rename it"
)


@pytest.fixture
def clashing(tmp_path: Path) -> Path:
    """A site with clashkit 0.1.0, whose protocol takes cosim's name ``greedy``."""
    site = tmp_path / "site"
    entry_points = {
        "cosim.protocols": {"greedy": "clashkit.greedy:Greedy", "mine": "clashkit.greedy:Greedy"}
    }
    return write_package(site, "clashkit", "0.1.0", entry_points, {"clashkit/greedy.py": GREEDY})


@pytest.mark.parametrize("command", ["check", "run"])
def test_a_run_using_a_registry_with_a_clash_is_refused_in_one_line_naming_both_packages(
    clashing: Path, tmp_path: Path, command: str
):
    with on_path(clashing):
        done = cosim_main(command, "warehouse-random", *_out(command, tmp_path))
    assert done.returncode == 2
    assert done.stderr == f"cosim: error: {CLASH}\n"
    assert not (tmp_path / "r").exists()


def _out(command: str, tmp_path: Path) -> list[str]:
    return ["--out", str(tmp_path / "r"), "--duration-s", "1"] if command == "run" else []


def test_cosim_plugins_lists_a_clash_marked_among_the_entries_and_exits_2(clashing: Path):
    with on_path(clashing):
        done = cosim_main("plugins", "protocol")
    lines = done.stdout.splitlines()
    assert lines[0] == "assignment protocols (cosim.protocols): 6"  # 5 names, 1 clash
    [marked] = [line for line in lines if "CLASH" in line]
    assert marked.split()[:2] == ["greedy", "CLASH:"]
    assert marked.endswith(CLASH.split("'greedy' is ", 1)[1])
    mine = next(line for line in lines if line.split()[:1] == ["mine"])
    assert mine.split()[1:3] == ["clashkit", "0.1.0"]
    assert done.returncode == 2
    assert done.stderr.startswith("cosim: error: registered twice (CLASH above): cosim.protocols")
    assert done.stderr.count("\n") == 1


def test_cosim_plugins_names_the_clash_in_a_fresh_process_too(clashing: Path):
    done = cosim(env_with(clashing), "plugins", "protocol")
    assert done.returncode == 2, done.stderr
    assert "  greedy" in done.stdout and "CLASH: registered by cosim" in done.stdout


def test_cosim_plugins_shows_each_entrys_package_version():
    from importlib.metadata import version

    done = cosim_main("plugins", "planner")
    line = next(li for li in done.stdout.splitlines() if li.split()[:1] == ["astar"])
    assert line.split()[1:3] == ["cosim", version("cosim")]

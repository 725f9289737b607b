"""The documentation site builds, strictly, and shows what the references promise."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

from cosim.runner.summary_keys import declared_keys
from tests.conftest import REPO, cosim_main

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def site(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("site")
    env = {**os.environ, "NO_MKDOCS_2_WARNING": "1", "DISABLE_MKDOCS_2_WARNING": "true"}
    mkdocs = Path(sys.executable).parent / "mkdocs"
    done = subprocess.run(
        [str(mkdocs), "build", "--strict", "--quiet", "--site-dir", str(out)],
        cwd=REPO, capture_output=True, text=True, env=env, timeout=300,
    )  # fmt: skip
    assert done.returncode == 0, done.stdout + done.stderr
    return out


def test_the_site_has_every_page_of_the_navigation(site):
    for page in (
        "index.html",
        "getting-started.html",
        "concepts/kernel.html",
        "concepts/architecture.html",
        "tutorials/write-a-protocol.html",
        "reference/scenario-keys.html",
        "reference/tables.html",
        "reference/summary.html",
        "reference/cli.html",
        "reference/api.html",
        "reference/registries.html",
    ):
        assert (site / page).is_file(), page


def test_every_key_of_the_humans_scenario_appears_in_the_built_site(site):
    printed = cosim_main("check", "warehouse-humans", "--print").stdout
    html = (site / "reference" / "scenario-keys.html").read_text()
    for key in re.findall(r"^(\w+) = ", printed, flags=re.M):
        assert f"<code>{key}</code>" in html, key


def test_the_api_reference_renders_the_run_function_and_the_contracts(site):
    html = (site / "reference" / "api.html").read_text()
    for name in ("cosim.run", "RunContext", "ProtocolFleet", "ControlInputs", "TableSpec"):
        assert name in html, name


def test_names_in_angle_brackets_units_and_every_summary_key_are_in_the_built_site(site):
    keys = (site / "reference" / "scenario-keys.html").read_text()
    assert "Twist on /&lt;robot&gt;/cmd_vel" in keys
    assert "publishes /vicon/&lt;subject&gt;/&lt;segment&gt;)" in keys
    assert "<td>dBm</td>" in keys and "<td>dB</td>" in keys and "<td>1/m</td>" in keys
    registries = (site / "reference" / "registries.html").read_text()
    assert "a Unity scene's /&lt;robot&gt;/cmd_vel" in registries
    summary = (site / "reference" / "summary.html").read_text()
    for key in declared_keys():
        assert f"<td><code>{key}</code></td>" in summary, key

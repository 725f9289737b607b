"""``cosim check-plugin``: every built-in passes the checks a plugin is put through."""

from __future__ import annotations

import importlib.util
import os
import re
import subprocess
import sys
from collections.abc import Mapping
from pathlib import Path
from typing import Any, ClassVar

import pytest

from adapters.assignment.contract import EpochView, ProtocolBase
from cosim.core.adapter import RunContext
from cosim.core.registry import installed_groups, registered
from cosim.testing.checks import registry_of
from tests.conftest import REPO, cosim_main

BUILT_INS = [
    f"{group.entry_points}:{name}"
    for group in installed_groups()
    for name in registry_of(group).names()
]


@pytest.fixture(scope="module")
def needs(tmp_path_factory: pytest.TempPathFactory) -> dict[str, list[str]]:
    """Scenario keys a built-in needs to have something to do (a file to replay, ...)."""
    folder = tmp_path_factory.mktemp("needs")
    delays = folder / "delays.csv"
    delays.write_text("delay_ms\n3.0\n5.5\n2.0\n")
    track = folder / "track.csv"  # robot_1 creeping north from its dock
    track.write_text(
        "t_s,x_m,y_m,yaw_rad\n"
        + "".join(f"{k / 10:.1f},7.04,{0.63 + k / 100:.2f},1.570796\n" for k in range(100))
    )
    return {
        "cosim.adapters:mocap": ["mocap.source='simulated'"],
        "cosim.latency_models:empirical": [f"network.latency_csv='{delays}'"],
        "cosim.mocap_sources:bag": [f"mocap.file='{track}'"],
        "cosim.topologies:explicit": ['network.edges=[["robot_1", "robot_2"]]'],
        "cosim.topologies:range": ["network.range_m=10.0"],
        "cosim.agent_actions:bid": ["assignment.protocol='agent_bids'"],
        "cosim.protocols:agent_bids": [
            "robots.driver='agents'",
            "agents.action='bid'",
            "agents.policy='random'",
        ],
        # the tutorial's model: one robot, its speed, goal and lidar sectors
        "cosim.agent_policies:sb3": [
            "robots.count=1",
            "agents.observe=['velocity', 'goal', 'lidar']",
            f"agents.policy_file='{REPO / 'studies' / 'policies' / 'lab_goals_ppo.zip'}'",
        ],
    }


def test_the_built_ins_of_every_group_are_checked():
    groups = {entry.split(":")[0] for entry in BUILT_INS}
    assert len(groups) == len(installed_groups()) >= 13
    assert {"cosim.protocols:greedy", "cosim.controllers:dwa", "cosim.sections:network"} <= set(
        BUILT_INS
    )


@pytest.mark.parametrize("entry", BUILT_INS)
def test_every_built_in_passes_check_plugin(entry, needs):
    if (
        entry == "cosim.agent_policies:sb3"
        and importlib.util.find_spec("stable_baselines3") is None
    ):
        pytest.skip("the sb3 policy needs the rl extra (Stable-Baselines3), not installed here")
    args = [arg for setting in needs.get(entry, []) for arg in ("--set", setting)]
    done = cosim_main("check-plugin", entry, *args)
    assert done.returncode == 0, done.stdout + done.stderr
    lines = done.stdout.splitlines()
    assert re.fullmatch(r"checking .* \(.*, cosim [\w.+]+\)", lines[0]), lines[0]
    assert all(line.split()[0] in ("ok", "skip") for line in lines[1:-1]), done.stdout
    assert lines[-1].startswith(f"{entry.split(':')[1]}: ") and "checks passed" in lines[-1]


@pytest.mark.parametrize(
    ("args", "said"),
    [
        (["greedyy"], "no plugin 'greedyy' in any registry; did you mean 'greedy'?"),
        (["none"], "'none' is registered in cosim.loss_models, cosim.map_sharing, cosim.traffic"),
        (["protocls:cbba"], "no registry 'protocls'; did you mean 'protocols'?"),
        (
            ["cbba", "--set", "assignment.period=1"],
            "--set assignment.period: [assignment] has no key 'period'; did you mean 'period_ms'?",
        ),
        (["cbba", "--set", "asignment.period_ms=1"], "did you mean 'assignment'?"),
        (["cbba", "--set", "assignment.period_ms"], "expected section.key=value"),
        (["cbba", "--duration-s", "-1"], "-1 is not a duration"),
    ],
)
def test_an_unknown_or_ambiguous_name_or_a_bad_setting_is_one_line_and_status_2(args, said):
    done = cosim_main("check-plugin", *args)
    assert done.returncode == 2, done.stdout + done.stderr
    assert said in done.stderr + done.stdout
    assert done.stderr.count("\n") == 1 and "Traceback" not in done.stderr


class Nobody(ProtocolBase):
    """A user's protocol whose robots take no task."""

    name: ClassVar[str] = "nobody"

    def agent(self, epoch: EpochView) -> None:
        return None


def test_a_protocol_that_assigns_nobody_fails_naming_the_check_and_exits_3():
    with registered("cosim.protocols", "nobody", Nobody):
        done = cosim_main("check-plugin", "nobody")
    assert done.returncode == 3, done.stdout + done.stderr
    lines = done.stdout.splitlines()
    assert lines[0] == (
        "checking assignment protocol 'nobody' (tests.cosim.cli.test_checkplugin:Nobody, "
        "given in code)"
    )
    assert "FAIL assigns: no task of 3 claimed within 5 s of appearing" in done.stdout
    assert lines[-1] == "nobody: 1 of 10 checks failed: assigns"


class Undeclared:
    """A user's adapter whose summary key is declared nowhere."""

    name: ClassVar[str] = "undeclared"
    requires: ClassVar[tuple[str, ...]] = ()

    def __init__(self, run: RunContext) -> None: ...

    def start(self, run: RunContext) -> None: ...

    def finish(self, run: RunContext) -> Mapping[str, Any]:
        return {"undeclared_count": 1}


def test_a_summary_key_declared_nowhere_is_a_warning_and_the_plugin_passes():
    with registered("cosim.adapters", "undeclared", Undeclared):
        done = cosim_main("check-plugin", "undeclared")
    assert done.returncode == 0, done.stdout + done.stderr
    lines = done.stdout.splitlines()
    assert [line for line in lines if line.startswith("warn")] == [
        "warn declared: summary key undeclared_count declared nowhere: declare each in the "
        "summary_keys of the class that writes it (key -> cosim.core.summary.SummaryKey(unit, "
        "doc)), so the summary reference documents it"
    ]
    assert re.fullmatch(r"undeclared: \d+ checks passed \(1 with a warning\), 1 skipped", lines[-1])


BROKEN = {
    "METADATA": "Metadata-Version: 2.1\nName: halfplug\nVersion: 0.2\n",
    "entry_points.txt": "[cosim.protocols]\nhalf_auction = halfplug.auction:Auction\n",
}


def test_a_plugin_whose_module_does_not_import_fails_loads_in_its_package(tmp_path: Path):
    info = tmp_path / "halfplug-0.2.dist-info"
    info.mkdir()
    for name, text in BROKEN.items():
        (info / name).write_text(text)
    (tmp_path / "halfplug").mkdir()
    (tmp_path / "halfplug" / "__init__.py").write_text("")
    (tmp_path / "halfplug" / "auction.py").write_text("import numpyy\n")
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(tmp_path), str(REPO)])}
    done = subprocess.run(
        [sys.executable, "-m", "cosim", "check-plugin", "half_auction"],
        capture_output=True, text=True, env=env, timeout=120,
    )  # fmt: skip
    assert done.returncode == 3, done.stderr
    assert done.stdout.splitlines() == [
        "checking assignment protocol 'half_auction' (halfplug.auction:Auction, package halfplug)",
        "FAIL loads: halfplug.auction:Auction cannot be imported: ModuleNotFoundError: No module "
        "named 'numpyy'",
        "half_auction: 1 of 1 checks failed: loads",
    ]

"""Every key a run writes into summary.json is declared, with a unit and a meaning."""

from __future__ import annotations

import signal
from collections.abc import Mapping
from typing import Any, ClassVar

import pytest

import cosim
from adapters.mapping.bagmap import SUMMARY_KEYS as MAP_SUMMARY_KEYS
from adapters.unity.server import UnityOptions
from cosim.core.adapter import RunContext
from cosim.core.errors import CosimError
from cosim.core.plugins import PluginError
from cosim.core.summary import SummaryKey, key_problems
from cosim.runner.result import RunResult
from cosim.runner.stopping import RunStopped, StopRequest
from cosim.runner.summary_keys import RUN_KEYS, declared_keys, declared_summaries
from cosim.scenario.fields import unit_of
from cosim.testing import SMALL_WAREHOUSE
from cosim.testing.outcomes import VOLATILE

SMALL = dict(SMALL_WAREHOUSE)
PRESETS = {
    "warehouse-random": SMALL,
    "warehouse-rows": {"robots.count": 3},
    "warehouse-mapping": {"robots.count": 2, "mapping.share": "maps"},
    "lab-room": {},
    "fleet50": {"robots.count": 6},
    "warehouse-humans": {"robots.count": 3, "humans.workers": 3, "humans.forklifts": 1},
    "lab-real-in-virtual": {},  # a physical robot tracked over DDS: real time, nobody answers
    "lab-mixed": {},
}
"""Every preset, small: (preset, overrides)."""
LIVE_PRESETS = ("lab-real-in-virtual", "lab-mixed")
"""Presets tracking robots by live motion capture, which a run shorter than
``mocap.connect_timeout_s`` with nobody answering ends as failed."""
TOGGLES = {
    "simulated mocap": {"mocap.source": "simulated", "mocap.dropout": 0.2},
    "teleop driver": {"robots.driver": "teleop"},
    "waypoints driver": {"robots.driver": "waypoints"},
    "navigation driver": {"robots.driver": "navigation"},
    "agents driver": {"robots.driver": "agents"},
    "cbba": {"assignment.protocol": "cbba"},
    "greedy": {"assignment.protocol": "greedy"},
    "hungarian": {"assignment.protocol": "hungarian"},
    "mapping sharing scans": {"mapping.enabled": True, "mapping.share": "scans"},
    "physical robot on its odometry": {"physical.robots": ["robot_1"], "physical.pose": "odom"},
    "ns-3 radio": {"network.backend": "ns3"},
}
"""Features that add summary keys, each on the small warehouse-random."""
LIVE_ONLY = {
    "mocap_missing_bodies",  # a motion-capture system's
    "mocap_unity_poses",  # a Unity scene's
    "mocap_unity_not_in_map",
    "unity_frames_dropped",  # a Unity scene too slow to take the frames
    "unity_twists",  # the teleop driver with --unity: commands from a scene
    "unity_poses",  # mocap.source = 'unity'
}
"""Declared keys only a live outside system makes a run write."""


class _Broken:
    """An adapter whose code fails one second into the run."""

    name: ClassVar[str] = "broken"
    requires: ClassVar[tuple[str, ...]] = ()

    def __init__(self, run: RunContext) -> None:
        pass

    def start(self, run: RunContext) -> None:
        run.kernel.at(1_000_000_000, self.fail)

    def fail(self) -> None:
        raise RuntimeError("broken on purpose")

    def finish(self, run: RunContext) -> Mapping[str, Any]:
        return {}


def _stopper(request: StopRequest) -> type:
    """An adapter that, one second into the run, does what SIGINT's handler does."""

    class Stopper:
        name: ClassVar[str] = "stopper"
        requires: ClassVar[tuple[str, ...]] = ()

        def __init__(self, run: RunContext) -> None:
            pass

        def start(self, run: RunContext) -> None:
            run.kernel.at(1_000_000_000, lambda: request.handle(signal.SIGINT))

        def finish(self, run: RunContext) -> Mapping[str, Any]:
            return {}

    return Stopper


def _runs() -> dict[str, RunResult]:
    """A short run of every preset, feature, failure, stop and live endpoint."""
    results = {}
    for preset, overrides in PRESETS.items():
        scenario = cosim.load_scenario(preset, overrides)
        if preset in LIVE_PRESETS:  # nobody answers: the run fails at its end, its keys kept
            with pytest.raises(CosimError) as unanswered:
                cosim.run(scenario, duration_s=1.0)
            assert unanswered.value.kept is not None, unanswered.value
            results[preset] = unanswered.value.kept
            continue
        results[preset] = cosim.run(scenario, duration_s=1.0 if "lab" in preset else 4.0)
    for feature, overrides in TOGGLES.items():
        scenario = cosim.load_scenario("warehouse-random", {**SMALL, **overrides})
        results[feature] = cosim.run(scenario, duration_s=1.5)
    small = cosim.load_scenario("warehouse-random", SMALL)
    results["unity"] = cosim.run(small, duration_s=1.0, unity=UnityOptions(port=0))
    with pytest.raises(PluginError) as failed:
        cosim.run(small, duration_s=2.0, adapters=[_Broken])
    assert failed.value.kept is not None
    results["failed"] = failed.value.kept
    request = StopRequest()
    with pytest.raises(RunStopped) as stopped:
        # the runner looks at the request every 0.1 s of wall time: a long run meets it
        cosim.run(small, duration_s=1e6, adapters=[_stopper(request)], stop=request)
    assert stopped.value.result is not None
    results["stopped"] = stopped.value.result
    return results


def undeclared(results: Mapping[str, RunResult], declared: Mapping[str, SummaryKey]) -> list[str]:
    """``key (run)`` for every key a run wrote that nothing declares."""
    return sorted(
        f"{key} ({name})"
        for name, result in results.items()
        for key in result.summary
        if key not in declared
    )


@pytest.mark.slow
def test_every_key_the_presets_and_features_write_is_declared_and_every_declared_one_written():
    results = _runs()
    declared = declared_keys()
    assert undeclared(results, declared) == []
    written = {key for result in results.values() for key in result.summary}
    assert set(declared) - written == LIVE_ONLY  # no declaration of a key nothing writes
    assert results["failed"].summary["failure"]["kind"] == "plugin"
    assert results["stopped"].summary["stopped"] == "SIGINT"
    print(f"{len(written)} keys written by {len(results)} runs, all of {len(declared)} declared")


def test_a_small_run_writes_only_declared_keys():
    result = cosim.run(cosim.load_scenario("warehouse-random", SMALL), duration_s=3.0)
    assert len(result.summary) > 50
    assert undeclared({"small": result}, declared_keys()) == []


def test_a_key_nothing_declares_is_found():
    result = cosim.run(cosim.load_scenario("warehouse-random", SMALL), duration_s=1.0)
    declared = {k: v for k, v in declared_keys().items() if k != "lidar_rays"}
    assert undeclared({"small": result}, declared) == ["lidar_rays (small)"]


def _every_declaration() -> list[tuple[str, str, SummaryKey]]:
    found = [(s.writer, key, value) for s in declared_summaries() for key, value in s.keys.items()]
    return found + [("cosim map", key, value) for key, value in MAP_SUMMARY_KEYS.items()]


def test_every_declared_key_has_a_unit_and_a_one_line_meaning():
    declarations = _every_declaration()
    assert len(declarations) > 130
    problems = [
        f"{writer}: {key} {said}"
        for writer, key, value in declarations
        for said in key_problems(value)
    ]
    assert problems == []


def test_a_key_whose_name_carries_a_unit_is_declared_in_that_unit():
    for writer, key, value in _every_declaration():
        carried = unit_of(key)
        if carried:
            assert value.unit == carried, f"{writer}: {key}"


def test_a_key_two_writers_declare_has_one_unit():
    units: dict[str, set[str]] = {}
    for _writer, key, value in _every_declaration()[: -len(MAP_SUMMARY_KEYS)]:
        units.setdefault(key, set()).add(value.unit)
    assert {key: found for key, found in units.items() if len(found) > 1} == {}
    mocap = [s for s in declared_summaries() if "mocap_poses" in s.keys]
    assert [s.writer for s in mocap] == ["adapter `mocap`", "adapter `physical`"]


def test_the_volatile_keys_are_those_two_runs_are_compared_without():
    volatile = {
        key for _, key, value in _every_declaration()[: -len(MAP_SUMMARY_KEYS)] if value.volatile
    }
    assert volatile == VOLATILE


def test_the_runner_comes_first_then_the_unity_endpoint_then_every_entry_declaring_keys():
    summaries = declared_summaries()
    assert summaries[0].keys is RUN_KEYS and summaries[0].package == "cosim"
    assert summaries[1].writer == "the Unity endpoint (`cosim run --unity`)"
    writers = [s.writer for s in summaries]
    for writer in (
        "adapter `fleet`",
        "adapter `navigation`",
        "network backend `links`",
        "assignment protocol `hungarian`",
        "motion capture source `ros2`",
    ):
        assert writer in writers
    assert all(s.keys for s in summaries)


def test_an_entry_given_in_code_counts_with_its_declaration():
    class Battery:
        summary_keys: ClassVar[Mapping[str, SummaryKey]] = {
            "battery_lowest": SummaryKey("fraction", "lowest charge at the end"),
        }

    assert "battery_lowest" not in declared_keys()
    assert declared_keys(Battery)["battery_lowest"].unit == "fraction"

"""Compiling and caching the numba kernels ahead (``python -m cosim.runner.warmup``)."""

from __future__ import annotations

from types import SimpleNamespace

import pytest

import cosim
from cosim.runner import execute
from cosim.runner.warmup import WARMUPS, main, warm_up


@pytest.fixture
def runs(monkeypatch: pytest.MonkeyPatch) -> list[tuple[str, float, int]]:
    """Stand in for the runs: each records (name, duration s, robots) and compiles 1.5 s."""
    done: list[tuple[str, float, int]] = []

    def fake_run(scenario, **_kwargs):
        assert not _kwargs, "a warm-up run writes no folder"
        done.append((scenario.name, scenario.scenario.duration_s, scenario.robots.count))
        return SimpleNamespace(compile_time_s=1.5)

    monkeypatch.setattr(execute, "run", fake_run)
    return done


def test_every_warm_up_preset_loads_and_takes_its_duration():
    for name, duration_s, overrides in WARMUPS:
        scenario = cosim.load_scenario(name, overrides=overrides).with_duration(duration_s)
        assert scenario.name == name and scenario.scenario.duration_s == duration_s


def test_a_warm_up_runs_every_preset_briefly_in_order_and_adds_up_the_compile_time(runs):
    assert warm_up() == pytest.approx(1.5 * len(WARMUPS))
    assert [(name, duration) for name, duration, _ in runs] == [
        (name, duration_s) for name, duration_s, _ in WARMUPS
    ]


def test_a_warm_up_of_chosen_presets_runs_only_those(runs):
    assert warm_up(["fleet50"]) == pytest.approx(1.5)
    assert runs == [("fleet50", 5.0, 50)]
    assert warm_up([]) == 0.0 and len(runs) == 1


def test_the_command_says_how_long_numba_compiled(runs, capsys):
    assert main(["warehouse-random", "warehouse-rows"]) == 0
    said = capsys.readouterr().out
    assert said.startswith("numba kernels compiled and cached in 3.0 s (warm-up ")
    assert said.rstrip().endswith("s): runs load them from the cache")
    assert [name for name, _, _ in runs] == ["warehouse-random", "warehouse-rows"]


def test_the_command_says_already_cached_when_nothing_compiled(monkeypatch, capsys):
    monkeypatch.setattr(execute, "run", lambda scenario: SimpleNamespace(compile_time_s=0.0))
    assert main([]) == 0
    assert capsys.readouterr().out.startswith("numba kernels already cached (warm-up ")

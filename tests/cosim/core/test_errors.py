"""One root for every error cosim raises on purpose, each a one-line message."""

import pytest

from cosim.core import errors
from cosim.core.errors import (
    BagError,
    BridgeError,
    ConfigError,
    CosimError,
    ExportError,
    RegistryError,
    ScenarioError,
    WireError,
    WorkerError,
)
from tests.conftest import cosim_main

LEAVES = [
    ConfigError,
    ScenarioError,
    RegistryError,
    ExportError,
    BagError,
    WorkerError,
    BridgeError,
    WireError,
]


def test_every_error_of_cosim_is_a_cosim_error_and_nothing_else_is_declared():
    declared = {
        v for v in vars(errors).values() if isinstance(v, type) and issubclass(v, BaseException)
    }
    assert declared == {CosimError, *LEAVES}
    assert all(issubclass(leaf, CosimError) and leaf is not CosimError for leaf in LEAVES)


@pytest.mark.parametrize("leaf", LEAVES, ids=lambda c: c.__name__)
def test_the_leaves_are_distinct_so_a_caller_can_catch_one_kind(leaf):
    others = [other for other in LEAVES if other is not leaf]
    assert not any(issubclass(leaf, other) for other in others)


def test_an_error_keeps_nothing_unless_a_run_hands_it_what_ran():
    error = BridgeError("DDS went away")
    assert error.kept is None and CosimError.kept is None
    error.kept = {"t_s": 1.5}
    assert BridgeError("another").kept is None


def test_saying_what_was_kept_extends_the_one_line_message():
    error = BridgeError("SUMO closed the connection at t = 3.2 s")
    error.say_kept("the results so far are in runs/x")
    assert str(error) == "SUMO closed the connection at t = 3.2 s; the results so far are in runs/x"
    assert "\n" not in str(error)


def test_the_command_line_prints_a_cosim_error_on_one_line_and_exits_with_status_2(tmp_path):
    done = cosim_main("check", str(tmp_path / "nowhere.yaml"))
    assert done.returncode == 2
    (line,) = done.stderr.splitlines()
    assert line.startswith("cosim: error: ") and "nowhere.yaml" in line

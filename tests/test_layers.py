"""The floors of the house (docs/architecture.md), checked on the import statements of every module.

``models/`` is pure; ``cosim/core/`` is what adapters rely on and imports no other floor;
``cosim/scenario/`` sits on the core; adapters use the core and the scenario, never the
user's shell (command line, runner, studies, recording, plotting); clients of outside
systems live with their capability in ``adapters/``, never in ``cosim/``.
"""

import ast
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
OUTSIDE_SYSTEMS = {"libsumo", "sumolib", "traci", "cyclonedds", "motioncapture"}
LONGEST_MODULE = 500


def _imports(path: Path) -> set[str]:
    """Every module a file imports, at the top or inside a function."""
    tree = ast.parse(path.read_text())
    found: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found |= {alias.name for alias in node.names}
        elif isinstance(node, ast.ImportFrom) and node.module:
            found.add(node.module)
            if node.module in ("cosim", "adapters", "models"):  # from cosim import core
                found |= {f"{node.module}.{alias.name}" for alias in node.names}
    return found


def _modules(*folder: str) -> list[Path]:
    return sorted(ROOT.joinpath(*folder).rglob("*.py"))


def _ids(path: Path) -> str:
    return str(path.relative_to(ROOT))


def _within(module: str, package: str) -> bool:
    return module == package or module.startswith(package + ".")


@pytest.mark.parametrize("path", _modules("models"), ids=_ids)
def test_models_never_import_simpy_cosim_or_adapters(path):
    bad = {m for m in _imports(path) if m.split(".")[0] in {"simpy", "cosim", "adapters"}}
    assert not bad, f"{path} imports {bad}"


@pytest.mark.parametrize("path", _modules("cosim", "core"), ids=_ids)
def test_the_core_rests_on_the_standard_library_simpy_and_numpy_alone(path):
    allowed = set(sys.stdlib_module_names) | {"simpy", "numpy"}
    bad = {
        m for m in _imports(path) if not _within(m, "cosim.core") and m.split(".")[0] not in allowed
    }
    assert not bad, f"{path} imports {bad}"


@pytest.mark.parametrize("path", _modules("cosim", "scenario"), ids=_ids)
def test_the_scenario_rests_on_the_core_and_never_imports_the_shell_or_adapters(path):
    allowed = ("cosim.core", "cosim.scenario")
    bad = {
        m
        for m in _imports(path)
        if m.split(".")[0] == "adapters"
        or (m.split(".")[0] == "cosim" and not any(_within(m, a) for a in allowed))
    }
    assert not bad, f"{path} imports {bad}"


@pytest.mark.parametrize("path", _modules("adapters"), ids=_ids)
def test_adapters_use_only_the_core_and_the_scenario_of_cosim_never_the_shell(path):
    allowed = ("cosim.core", "cosim.scenario")
    bad = {
        m
        for m in _imports(path)
        if m.split(".")[0] == "cosim" and not any(_within(m, a) for a in allowed)
    }
    assert not bad, f"{path} imports {bad}"


@pytest.mark.parametrize("path", _modules("cosim"), ids=_ids)
def test_no_module_of_cosim_talks_to_an_outside_system_itself(path):
    bad = {m for m in _imports(path) if m.split(".")[0] in OUTSIDE_SYSTEMS}
    assert not bad, f"{path} imports {bad}: clients of outside systems live in adapters/"


@pytest.mark.parametrize(
    "path", _modules("cosim") + _modules("adapters") + _modules("models"), ids=_ids
)
def test_every_module_stays_under_500_lines(path):
    lines = len(path.read_text().splitlines())
    assert lines <= LONGEST_MODULE, f"{path} has {lines} lines: split it by concept"


def test_the_rules_see_every_floor():
    # a rule over an empty folder would pass without checking anything
    for folder in (("models",), ("cosim", "core"), ("cosim", "scenario"), ("adapters",)):
        assert len(_modules(*folder)) >= 5, folder

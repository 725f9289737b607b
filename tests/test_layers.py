"""The layering rule of DESIGN.md, checked on the import statements of every module."""

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
CORE = [
    "kernel",
    "bus",
    "link",
    "messages",
    "hosts",
    "records",
    "rng",
    "timebase",
    "errors",
    "adapter",
]


def _imports(path: Path) -> set[str]:
    tree = ast.parse(path.read_text())
    found: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found |= {alias.name for alias in node.names}
        elif isinstance(node, ast.ImportFrom) and node.module:
            found.add(node.module)
    return found


def _modules(package: str) -> list[Path]:
    return sorted((ROOT / package).rglob("*.py"))


@pytest.mark.parametrize("path", _modules("models"), ids=lambda p: str(p.relative_to(ROOT)))
def test_models_never_import_simpy_cosim_or_adapters(path):
    bad = {m for m in _imports(path) if m.split(".")[0] in {"simpy", "cosim", "adapters"}}
    assert not bad, f"{path} imports {bad}"


@pytest.mark.parametrize("path", _modules("adapters"), ids=lambda p: str(p.relative_to(ROOT)))
def test_adapters_never_import_the_command_line_or_the_runner(path):
    bad = {m for m in _imports(path) if m in {"cosim.cli", "cosim.runner", "cosim.study"}}
    assert not bad, f"{path} imports {bad}"


def _core_files(name: str) -> list[Path]:
    module = ROOT / "cosim" / f"{name}.py"
    return [module] if module.exists() else sorted((ROOT / "cosim" / name).glob("*.py"))


@pytest.mark.parametrize("name", CORE)
def test_the_kernel_core_never_imports_models_or_adapters(name):
    files = _core_files(name)
    assert files, f"no module cosim.{name}"
    for path in files:
        bad = {m for m in _imports(path) if m.split(".")[0] in {"models", "adapters"}}
        assert not bad, f"{path} imports {bad}"

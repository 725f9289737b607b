"""The floors of the house (docs/architecture.md), checked on the import statements of every module.

``models/`` is pure; ``cosim/core/`` is what adapters rely on, on the standard library,
simpy and numpy alone; ``cosim/scenario/`` sits on the core; adapters use the core and the
scenario, never the user's shell (command line, runner, studies, recording, plotting);
clients of outside systems live with their capability in ``adapters/``, never in
``cosim/``. No two files, and no two capability folders, import each other in a loop
(imports inside functions and under ``TYPE_CHECKING`` count).
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


def _module_name(path: Path) -> str:
    parts = list(path.relative_to(ROOT).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


ALL = _modules("cosim") + _modules("adapters") + _modules("models")
MODULES = {_module_name(p): p for p in ALL}


def _resolve(name: str) -> str | None:
    """The module of ours that ``name`` (a module or a name in one) is, or None."""
    while name and name not in MODULES:
        name = name.rpartition(".")[0]
    return name or None


def _graph() -> dict[str, set[str]]:
    """Module -> the modules of ours it imports, anywhere in it."""
    graph = {}
    for name, path in MODULES.items():
        targets = set()
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Import):
                found = [alias.name for alias in node.names]
            elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
                found = [f"{node.module}.{alias.name}" for alias in node.names]
            else:
                continue
            for imported in found:
                if imported.split(".")[0] in ("cosim", "models", "adapters"):
                    target = imported if imported in MODULES else _resolve(imported)
                    if target is not None and target != name:
                        targets.add(target)
        graph[name] = targets
    return graph


def _cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components of more than one node (Tarjan)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found: list[list[str]] = []

    def visit(node: str) -> None:
        index[node] = low[node] = len(index)
        stack.append(node)
        on_stack.add(node)
        for other in sorted(graph.get(node, ())):
            if other not in index:
                visit(other)
                low[node] = min(low[node], low[other])
            elif other in on_stack:
                low[node] = min(low[node], index[other])
        if low[node] == index[node]:
            component = []
            while True:
                other = stack.pop()
                on_stack.discard(other)
                component.append(other)
                if other == node:
                    break
            if len(component) > 1:
                found.append(sorted(component))

    for node in sorted(graph):
        if node not in index:
            visit(node)
    return found


def capability(module: str) -> str:
    """The folder a module belongs to: ``adapters.<capability>``, ``models.<capability>``,
    ``cosim.core`` (with its messages) or a package of the shell; a file at a floor's root
    is its own."""
    parts = module.split(".")
    if parts[:2] == ["cosim", "core"]:
        return "cosim.core"
    if len(parts) >= 3 or ROOT.joinpath(*parts).is_dir():
        return ".".join(parts[:2])
    return module


def test_no_files_import_each_other_in_a_loop():
    assert _cycles(_graph()) == []


def test_no_capability_folders_import_each_other_in_a_loop():
    folders: dict[str, set[str]] = {}
    for module, targets in _graph().items():
        mine = capability(module)
        folders.setdefault(mine, set()).update(
            capability(t) for t in targets if capability(t) != mine
        )
    assert _cycles(folders) == []


def test_the_cycle_check_finds_a_loop_and_a_loop_through_three():
    assert _cycles({"a": {"b"}, "b": {"a"}, "c": set()}) == [["a", "b"]]
    assert _cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}}) == [["a", "b", "c"]]
    assert _cycles({"a": {"b"}, "b": {"c"}, "c": set()}) == []


def test_unity_lives_in_one_place():
    shell = [p for p in _modules("cosim") if "unity" in p.stem]
    assert shell == [], "Unity belongs to adapters/unity/"
    assert {p.stem for p in _modules("adapters", "unity")} >= {"server", "pose_source", "inbound"}


def _is_face(path: Path) -> bool:
    """A package's ``__init__.py`` that only hands names on (or says what is inside)."""
    tree = ast.parse(path.read_text())
    return path.name == "__init__.py" and not any(
        isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef)
        for node in tree.body
    )


def _tested_by(test: Path, module: str) -> bool:
    """Whether a test file imports ``module`` (or a name from it)."""
    if not test.is_file():
        return False
    package, _, leaf = module.rpartition(".")
    for node in ast.walk(ast.parse(test.read_text())):
        if isinstance(node, ast.Import) and any(a.name == module for a in node.names):
            return True
        if isinstance(node, ast.ImportFrom) and node.module == module:
            return True
        if (
            isinstance(node, ast.ImportFrom)
            and node.module == package
            and any(a.name == leaf for a in node.names)
        ):
            return True
    return False


def untested(path: Path) -> bool:
    """Whether a source module has no test file: ``tests/<its path>/test_<name>.py``, or its
    package's ``test_<package>.py`` importing it (``test_package.py`` for a package's own
    ``__init__.py``)."""
    folder = ROOT / "tests" / path.relative_to(ROOT).parent
    if path.name == "__main__.py" or _is_face(path):
        return False
    if path.name == "__init__.py":
        names = [f"test_{path.parent.name}.py", "test_package.py"]
        return not any((folder / name).is_file() for name in names)
    if (folder / f"test_{path.stem}.py").is_file():
        return False
    return not _tested_by(folder / f"test_{path.parent.name}.py", _module_name(path))


def test_every_source_module_has_a_test_file():
    missing = [_ids(p) for p in ALL if untested(p)]
    assert missing == [], f"{len(missing)} modules without a test file: {missing}"


def test_the_rules_see_every_floor():
    # a rule over an empty folder would pass without checking anything
    for folder in (("models",), ("cosim", "core"), ("cosim", "scenario"), ("adapters",)):
        assert len(_modules(*folder)) >= 5, folder

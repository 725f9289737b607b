"""The package's names (cosim/__init__.py): the Python API, each loaded on first use."""

import subprocess
import sys

import pytest

import cosim
from cosim.core import errors
from cosim.runner import execute, result
from cosim.scenario import arguments, loader, model
from tests.conftest import REPO

DEFINED_IN = {
    "ArgumentError": arguments,
    "BridgeError": errors,
    "ConfigError": errors,
    "CosimError": errors,
    "ExportError": errors,
    "RegistryError": errors,
    "ScenarioError": errors,
    "RunResult": result,
    "run": execute,
    "Scenario": model,
    "load_scenario": loader,
}


@pytest.mark.parametrize("part", ["cosim", "cosim.core.bus", "cosim.cli.main"])
def test_importing_cosim_or_a_part_of_it_loads_neither_pandas_nor_the_runner(part):
    code = (
        f"import sys, {part}\n"
        "print(sorted(m for m in ('pandas', 'cosim.runner.execute') if m in sys.modules))\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", code], cwd=REPO, capture_output=True, text=True, check=True
    )
    assert done.stdout.strip() == "[]"


def test_every_name_of_the_package_is_the_one_its_module_defines():
    assert set(cosim.__all__) == {*DEFINED_IN, "study"}
    for name, module in DEFINED_IN.items():
        assert getattr(cosim, name) is getattr(module, name), name
    star: dict[str, object] = {}
    exec("from cosim import *", star)
    assert {n for n in star if not n.startswith("__")} == set(cosim.__all__)
    assert set(cosim.__all__) <= set(dir(cosim))


def test_a_name_the_package_does_not_have_is_an_attribute_error():
    with pytest.raises(AttributeError, match="module 'cosim' has no attribute 'nope'"):
        _ = cosim.nope  # type: ignore[attr-defined]
    assert not hasattr(cosim, "load_study")

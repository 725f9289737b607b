"""The kit's package: its names, imported on first use, and a plugin that costs nothing."""

import subprocess
import sys

import pytest

import cosim.testing
from cosim.testing.timing import assert_latency
from tests.conftest import REPO


def test_every_name_of_the_kit_comes_from_the_module_that_defines_it():
    assert cosim.testing.assert_latency is assert_latency
    assert set(cosim.testing.__all__) <= set(dir(cosim.testing))
    for name in cosim.testing.__all__:
        assert getattr(cosim.testing, name) is not None, name
    with pytest.raises(AttributeError, match="has no attribute 'assert_fast'"):
        _ = cosim.testing.assert_fast


def test_loading_the_pytest_plugin_imports_neither_pandas_nor_the_runner():
    probe = (
        "import sys\n"
        "import cosim.testing.plugin\n"
        "print(sorted({'pandas', 'cosim.runner', 'numba'} & set(sys.modules)))\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", probe], capture_output=True, text=True, cwd=REPO, check=True
    )
    assert done.stdout.strip() == "[]"

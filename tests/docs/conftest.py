"""The pages run in this test process, shared by the tests of their blocks and outcomes."""

from __future__ import annotations

import pytest

from tests.docs.pages import PageRuns


@pytest.fixture(scope="session")
def page_runs(tmp_path_factory: pytest.TempPathFactory) -> PageRuns:
    """Each page of the documentation run at most once per test process, in its own clone."""
    return PageRuns(tmp_path_factory.mktemp("pages"))

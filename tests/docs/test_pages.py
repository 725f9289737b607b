"""Every command and code block of the getting-started page and the guides runs as its reader
would run it (``tests/docs/blocks.py`` says how each kind of block runs and what a fence's
test options change; ``test_tutorials.py`` does the same for the tutorials).

A page's blocks run in order in one clone of the repository (``tests/docs/clone.py``): a
test for a page's quick blocks, one for its slow blocks (from its first block that runs a
simulation, installs or starts processes), and in each a subtest per block, named by its
page, line and language; a block marked ``test-skip`` is a skipped subtest saying why.
"""

from __future__ import annotations

import pytest

from tests.docs.pages import PAGES, PageRuns, Part, parts, run_part

GUIDES = tuple(page for page in PAGES if not page.startswith("tutorials/"))


@pytest.mark.parametrize(
    "part",
    [
        pytest.param(part, id=part.name, marks=[pytest.mark.slow] if part.slow else [])
        for part in parts(GUIDES)
    ],
)
def test_the_blocks_of_a_page_run_as_its_reader_would_run_them(
    part: Part, page_runs: PageRuns, subtests: pytest.Subtests
):
    run_part(part, page_runs, subtests)

"""Running a page's blocks in order, in a clone of its own, as its reader would.

A page is a sequence: its commands, Python and files build on what the blocks before them
left in the folder (a run's folder, an installed package), so a block runs after every
earlier block of its page, once per test process (:class:`PageRuns` keeps the pages run so
far). A block whose earlier block failed is not run: it fails naming that block. Untitled
TOML excerpts stand alone and need no folder.
"""

from __future__ import annotations

import re
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

import pytest

from tests.conftest import REPO
from tests.docs.blocks import (
    Block,
    Kind,
    output_matches,
    read_page,
    shortened,
    study_overrides,
    with_study_keys,
)
from tests.docs.clone import Clone, Ran

DOCS = REPO / "docs"
PAGES = (
    "getting-started.md",
    *sorted(f"guides/{p.name}" for p in (DOCS / "guides").glob("*.md")),
    *sorted(f"tutorials/{p.name}" for p in (DOCS / "tutorials").glob("*.md")),
)
"""The pages whose blocks run: getting started, the guides, the tutorials."""
QUICK = frozenset({"scenarios", "check", "plugins"})
"""cosim commands that take a few seconds: a block of only these (and files) is not slow."""
CHECKED = (".py", ".toml")
"""The files a page's test checks; a page's other files (a CSV) are written, then read by
the commands that use them."""


def is_tested(block: Block) -> bool:
    """A block that is a test: all but output, illustrations and files checked by no one."""
    if block.kind is Kind.FILE:
        return Path(str(block.title)).suffix in CHECKED
    return block.kind is not Kind.OUTPUT


def is_slow(block: Block) -> bool:
    """A block that runs a simulation, starts processes or installs (see :data:`QUICK`)."""
    if block.skip is not None or block.kind in (Kind.FILE, Kind.EXCERPT):
        return False
    if block.kind is Kind.PYTHON:
        return True
    return not all(c.cosim_command in QUICK for c in block.commands())


@dataclass(frozen=True)
class Part:
    """The quick or the slow blocks of a page: a test each.

    A page's slow part begins at its first slow block (:func:`is_slow`) and holds every
    tested block after it but the excerpts (each block needs the blocks before it); the
    quick part holds the rest. The two may run in different test processes: the slow part
    then runs the quick blocks before it again, as the steps they are (files, checks).
    """

    page: str
    slow: bool
    blocks: tuple[Block, ...]

    @property
    def name(self) -> str:
        """``guides/runs.md:slow``."""
        return f"{self.page}:{'slow' if self.slow else 'quick'}"


def parts(pages: tuple[str, ...]) -> list[Part]:
    """The quick and the slow part of each page that has any."""
    found: list[Part] = []
    for page in pages:
        blocks = [b for b in read_page(DOCS, page) if is_tested(b)]
        first = next((b.index for b in blocks if is_slow(b)), None)
        slow = tuple(
            b
            for b in blocks
            if first is not None and b.index >= first and b.kind is not Kind.EXCERPT
        )
        quick = tuple(b for b in blocks if b not in slow)
        found += [Part(page, False, quick)] if quick else []
        found += [Part(page, True, slow)] if slow else []
    return found


def run_part(part: Part, page_runs: PageRuns, subtests: pytest.Subtests) -> PageRun:
    """Run the part's blocks in its page's clone, a subtest each (named by page and line)."""
    page = page_runs[part.page]
    for block in part.blocks:
        with subtests.test(msg=block.name):
            page.run_to(block)
    return page


@dataclass
class PageRun:
    """One page being run, block after block, in its clone."""

    page: str
    folder: Path
    blocks: list[Block] = field(init=False)
    done: int = 0
    failed: Block | None = None
    ran: dict[int, list[Ran]] = field(default_factory=dict)
    python: list[str] = field(default_factory=list)
    _clone: Clone | None = None

    def __post_init__(self) -> None:
        self.blocks = read_page(DOCS, self.page)

    @property
    def clone(self) -> Clone:
        """The page's clone, made on first use."""
        if self._clone is None:
            self._clone = Clone(self.folder / "cosim")
        return self._clone

    def run_to(self, block: Block) -> list[Ran]:
        """Run the page's blocks up to ``block`` (those not yet run), then ``block``.

        Returns:
            What ``block``'s commands, or its Python, did (empty for a file).

        Raises:
            pytest.fail.Exception: this block or an earlier one failed (naming it).
            pytest.skip.Exception: the block is marked ``test-skip``.
        """
        if block.kind is Kind.EXCERPT:
            check_excerpt(block)
            return []
        while self.done <= block.index:
            current = self.blocks[self.done]
            if self.failed is not None:
                pytest.fail(f"not run: {self.failed.name}, before it, failed", pytrace=False)
            if current.kind in (Kind.OUTPUT, Kind.EXCERPT) or current.skip is not None:
                self.done += 1
                continue
            try:
                self.ran[current.index] = self._run(current)
            except BaseException:
                self.failed = current
                raise
            self.done += 1
        if block.skip is not None:
            pytest.skip(f"{block.name}: {block.skip}")
        return self.ran.get(block.index, [])

    def python_ran(self) -> list[Ran]:
        """What the page's Python blocks did, in order."""
        return [
            ran for b in self.blocks if b.kind is Kind.PYTHON for ran in self.ran.get(b.index, [])
        ]

    def output_of(self, command: str) -> Ran:
        """What the page's command ``command`` (as the page writes it) did."""
        for results in self.ran.values():
            for ran in results:
                if ran.command.startswith(command):
                    return ran
        raise KeyError(f"{self.page} ran no command {command!r}")

    def _run(self, block: Block) -> list[Ran]:
        if block.kind is Kind.FILE:
            self._file(block)
            return []
        if block.kind is Kind.PYTHON:
            return [self._python(block)]
        results = []
        for command in block.commands():
            text = shortened(command, block.options)
            if command.cosim_command == "study":
                self._shorten_study(command.words, block)
            ran = self.clone.shell(text)
            results.append(ran)
            print(ran.told())
            if command.expected:
                missing = output_matches(command.expected, ran.output)
                if missing is not None:
                    said = f"line {command.line} did not print {missing!r}"
                    pytest.fail(f"{block.name}: {said}\n{ran.told()}", pytrace=False)
            elif ran.returncode != 0:
                said = f"line {command.line} failed"
                pytest.fail(f"{block.name}: {said}\n{ran.told()}", pytrace=False)
        return results

    def _shorten_study(self, words: list[str], block: Block) -> None:
        keys = study_overrides(block.options)
        if not keys:
            return
        at = words.index("study") + 1
        path = self.clone.root / words[at]
        self.clone.write(words[at], with_study_keys(path.read_text(), keys))

    def _python(self, block: Block) -> Ran:
        if block.is_test_module:
            module = self.folder / "block_tests" / f"test_line_{block.line}.py"
            module.parent.mkdir(exist_ok=True)
            module.write_text(block.code)
            ran = self.clone.shell(f".venv/bin/python -m pytest -q -p no:cacheprovider {module}")
            print(ran.told())
            passed = re.search(r"(\d+) passed", ran.stdout)
            if ran.returncode != 0 or passed is None:
                pytest.fail(f"{block.name}: its tests failed\n{ran.told()}", pytrace=False)
            return ran
        script = "\n".join([*self.python, block.code])
        ran = self.clone.python_code(script)
        print(ran.told())
        if ran.returncode != 0:
            pytest.fail(f"{block.name}: the page's Python failed\n{ran.told()}", pytrace=False)
        self.python.append(block.code)
        return ran

    def _file(self, block: Block) -> None:
        assert block.title is not None
        path = self.clone.write(block.title, block.code)
        if path.suffix == ".py":
            compile(block.code, block.title, "exec")
        elif path.suffix == ".toml":
            data = tomllib.loads(block.code)
            if path.name == "pyproject.toml":
                return  # a package: the page's own `pip install` builds it
            if "study" in data:
                code = f"from cosim.studies.validate import load_study; load_study({block.title!r})"
                ran = self.clone.python_code(code)
            else:
                ran = self.clone.shell(f".venv/bin/cosim check {block.title}")
            print(ran.told())
            if ran.returncode != 0:
                pytest.fail(f"{block.name}: {block.title} is refused\n{ran.told()}", pytrace=False)


def check_excerpt(block: Block) -> None:
    """An excerpt of a TOML file parses, once its ``...`` lines (elisions) are left out."""
    kept = "".join(line for line in block.code.splitlines(keepends=True) if line.strip() != "...")
    try:
        tomllib.loads(kept)
    except tomllib.TOMLDecodeError as error:
        pytest.fail(f"{block.name}: not TOML: {error}", pytrace=False)


class PageRuns:
    """The pages run in this test process, each once, in folders under ``root``."""

    def __init__(self, root: Path) -> None:
        self.root = root
        self.pages: dict[str, PageRun] = {}

    def __getitem__(self, page: str) -> PageRun:
        if page not in self.pages:
            folder = self.root / page.replace("/", "-").removesuffix(".md")
            folder.mkdir(parents=True)
            self.pages[page] = PageRun(page, folder)
        return self.pages[page]

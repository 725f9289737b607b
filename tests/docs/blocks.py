"""The fenced code blocks of a documentation page, and what running each of them means.

A page is read as its reader reads it: the blocks in order, each with its language and the
options of its fence. What a block is for follows from its language and title (the
contributor notes, ``docs/contributing.md``, give the same rules as a table):

- ``sh``, ``bash``: its commands run in order in the page's folder; each must exit 0.
- ``console``: its ``$`` lines are commands; the lines after one are what it prints, each of
  which must appear in its output (``...`` stands for anything); a command shown with its
  output may exit with an error (an error shown is an error expected).
- ``python``: runs after the page's earlier Python blocks, as one script; a block that
  defines ``test_*`` functions is a test module, run with pytest.
- any block with ``title="path"``: a file of the page, written to ``path`` and checked:
  Python compiles, TOML parses, a scenario file passes ``cosim check``, a study file loads
  (a ``pyproject.toml`` is built by the page's own ``pip install``).
- an untitled ``toml`` block: an excerpt (a section, entry points); it must parse, once its
  ``...`` lines (elisions) are left out.
- ``text``, ``json`` or no language: output or an illustration, not run.

A fence may carry test options as attributes, ```` ```sh {test-duration-s="10"} ````
(mkdocs renders the block as any other; a title goes among them, ``{title="x.toml"}``):

- ``test-duration-s="S"``: every ``cosim run``, ``check-plugin`` and ``standin`` of the
  block gets ``--duration-s S`` appended (the last one given wins); a ``cosim study FILE``
  runs a copy of ``FILE`` with ``[study] duration_s = S``; a ``make`` target gets
  ``ARGS='--duration-s S'`` (the Makefile passes it to its run).
- ``test-seeds="N"``: a ``cosim study FILE`` runs a copy of ``FILE`` with ``seeds = N``.
- ``test-skip="why"``: not run; the test reports it skipped, saying why (hardware, a
  cluster, a window).

Nothing else is changed: the commands run exactly as the page writes them.
"""

from __future__ import annotations

import re
import shlex
from dataclasses import dataclass, field
from enum import StrEnum
from pathlib import Path

SHELLS = frozenset({"sh", "bash"})
OUTPUTS = frozenset({"text", "json", ""})
OPTIONS = ("test-duration-s", "test-seeds", "test-skip")
"""The test options a fence may carry; any other ``test-`` attribute is a mistake."""
SHORTENED = frozenset({"run", "check-plugin", "standin"})
"""The cosim commands that take ``--duration-s``, appended under ``test-duration-s``."""
COSIM = ".venv/bin/cosim"
"""How every page calls cosim: the environment ``make demo`` made, from the clone's folder."""

_FENCE = re.compile(r"^```(?P<lang>[\w+-]*)[ \t]*(?P<rest>.*?)[ \t]*$")
_BRACES = re.compile(r"^\{(?P<body>.*)\}$")
_OPTION = re.compile(r'(?P<key>[\w-]+)="(?P<value>[^"]*)"')
_SHELL_ONLY = re.compile(r"[|<>;&`]|\$\(")


class Kind(StrEnum):
    """What a block is for."""

    SHELL = "shell"
    CONSOLE = "console"
    PYTHON = "python"
    FILE = "file"
    EXCERPT = "excerpt"
    OUTPUT = "output"


class PageError(ValueError):
    """A page's block that the tests cannot read: the message names the page and line."""


@dataclass(frozen=True)
class Command:
    """One command of a shell or console block.

    Attributes:
        line: the line of the page where it starts (1-based).
        text: the command as the page writes it, continuation lines joined, without its
            comment.
        expected: for a console command, the lines shown after it (its output); empty
            for a shell command.
    """

    line: int
    text: str
    expected: tuple[str, ...] = ()

    @property
    def words(self) -> list[str]:
        """The command's words, as the shell splits them."""
        return shlex.split(self.text)

    @property
    def program(self) -> str:
        """The program run: the first word that is not an environment assignment."""
        return next((w for w in self.words if not re.match(r"^\w+=", w)), "")

    @property
    def cosim_command(self) -> str | None:
        """``run``, ``study``, ... for a call of cosim; None for another program."""
        words = self.words
        if self.program not in (COSIM, "cosim") or words.index(self.program) + 1 >= len(words):
            return None
        return words[words.index(self.program) + 1]


@dataclass(frozen=True)
class Block:
    """One fenced block of a page.

    Attributes:
        page: the page's path relative to ``docs/`` (``guides/runs.md``).
        index: its position among the page's blocks (0-based).
        line: the line of its opening fence (1-based).
        lang: the fence's language (``""`` for none).
        code: its text, each line ending in a newline.
        title: the fence's ``title``, a path relative to the page's folder, or None.
        options: its test options (:data:`OPTIONS`), by name.
    """

    page: str
    index: int
    line: int
    lang: str
    code: str
    title: str | None = None
    options: dict[str, str] = field(default_factory=dict)

    @property
    def kind(self) -> Kind:
        """What the block is for (see the module's table)."""
        if self.title is not None:
            return Kind.FILE
        if self.lang in SHELLS:
            return Kind.SHELL
        if self.lang == "console":
            return Kind.CONSOLE
        if self.lang == "python":
            return Kind.PYTHON
        if self.lang == "toml":
            return Kind.EXCERPT
        return Kind.OUTPUT

    @property
    def skip(self) -> str | None:
        """Why the block is not run, or None."""
        return self.options.get("test-skip")

    @property
    def name(self) -> str:
        """``guides/runs.md:12 sh``: the page, the line and the language."""
        return f"{self.page}:{self.line} {self.lang or 'text'}"

    @property
    def is_test_module(self) -> bool:
        """A Python block that defines tests (run with pytest, not as a script)."""
        return self.lang == "python" and re.search(r"^def test_\w+\(", self.code, re.M) is not None

    def commands(self) -> list[Command]:
        """The commands of a shell or console block, in order.

        Raises:
            PageError: a console block's output before any command.
        """
        if self.kind is Kind.SHELL:
            return _shell_commands(self.code, self.line + 1)
        if self.kind is Kind.CONSOLE:
            return _console_commands(self.code, self.line + 1, self.name)
        return []


def read_page(docs: Path, page: str) -> list[Block]:
    """Every fenced block of ``docs/page``, in order.

    Raises:
        PageError: an unclosed fence, a malformed option or an unknown test option, naming
            the page and the line.
    """
    lines = (docs / page).read_text().splitlines(keepends=True)
    blocks: list[Block] = []
    i = 0
    while i < len(lines):
        opening = _FENCE.match(lines[i])
        if opening is None:
            i += 1
            continue
        start = i
        i += 1
        body: list[str] = []
        while i < len(lines) and lines[i].rstrip() != "```":
            body.append(lines[i])
            i += 1
        if i == len(lines):
            raise PageError(f"{page}:{start + 1}: a fence that is never closed")
        i += 1
        title, options = _options(opening.group("rest"), f"{page}:{start + 1}")
        lang = opening.group("lang")
        blocks.append(Block(page, len(blocks), start + 1, lang, "".join(body), title, options))
    return blocks


def _options(rest: str, where: str) -> tuple[str | None, dict[str, str]]:
    """The title and the test options of a fence's text after its language."""
    braces = _BRACES.match(rest)
    body = braces.group("body") if braces else rest
    found = {m.group("key"): m.group("value") for m in _OPTION.finditer(body)}
    if _OPTION.sub("", body).strip():
        raise PageError(f'{where}: fence options {rest!r}; expected key="value" pairs')
    if not braces and any(key.startswith("test-") for key in found):
        raise PageError(f"{where}: test options go in braces: {{{body.strip()}}}")
    title = found.pop("title", None)
    unknown = sorted(set(found) - set(OPTIONS))
    if unknown:
        raise PageError(f"{where}: unknown fence option {unknown[0]!r}; expected one of {OPTIONS}")
    return title, found


def _shell_commands(code: str, first_line: int) -> list[Command]:
    commands: list[Command] = []
    pending: list[str] = []
    start = first_line
    for number, raw in enumerate(code.splitlines(), start=first_line):
        text = strip_comment(raw).rstrip()
        if not pending:
            start = number
        if text.endswith("\\"):
            pending.append(text[:-1].strip())
            continue
        pending.append(text.strip())
        joined = " ".join(part for part in pending if part)
        pending = []
        if joined:
            commands.append(Command(start, joined))
    return commands


def _console_commands(code: str, first_line: int, name: str) -> list[Command]:
    commands: list[Command] = []
    for number, raw in enumerate(code.splitlines(), start=first_line):
        if raw.startswith("$ "):
            commands.append(Command(number, strip_comment(raw[2:]).strip()))
        elif raw.strip():
            if not commands:
                raise PageError(f"{name}: output before any `$ ` command")
            last = commands[-1]
            commands[-1] = Command(last.line, last.text, (*last.expected, raw.rstrip()))
    return commands


def strip_comment(line: str) -> str:
    """``line`` without its shell comment (a ``#`` starting a word, outside quotes)."""
    quote = ""
    escaped = False
    for i, char in enumerate(line):
        if escaped:
            escaped = False
        elif char == "\\" and quote != "'":
            escaped = True
        elif quote:
            quote = "" if char == quote else quote
        elif char in "'\"":
            quote = char
        elif char == "#" and (i == 0 or line[i - 1].isspace()):
            return line[:i]
    return line


def shortened(command: Command, options: dict[str, str]) -> str:
    """The command as the tests run it under the block's options (see the module's table).

    A ``cosim study`` is not rewritten here: its study file is (``study_overrides``).

    Raises:
        PageError: options that would have to change a pipeline or a redirection.
    """
    duration = options.get("test-duration-s")
    if duration is None:
        return command.text
    extra = ""
    if command.cosim_command in SHORTENED:
        extra = f" --duration-s {duration}"
    elif command.program == "make":
        extra = f" ARGS='--duration-s {duration}'"
    if extra and _SHELL_ONLY.search(command.text):
        raise PageError(f"line {command.line}: cannot append{extra} to {command.text!r}")
    return command.text + extra


def study_overrides(options: dict[str, str]) -> dict[str, int | float]:
    """``[study]`` keys a ``cosim study`` of the block runs with: ``duration_s``, ``seeds``."""
    keys: dict[str, int | float] = {}
    if "test-duration-s" in options:
        keys["duration_s"] = float(options["test-duration-s"])
    if "test-seeds" in options:
        keys["seeds"] = int(options["test-seeds"])
    return keys


def with_study_keys(text: str, keys: dict[str, int | float]) -> str:
    """A study file's text with ``[study]`` ``keys`` set (replaced where given, else added)."""
    lines = text.splitlines()
    try:
        header = next(i for i, line in enumerate(lines) if line.strip() == "[study]")
    except StopIteration:
        raise PageError("a study file without a [study] table") from None
    end = next(
        (i for i in range(header + 1, len(lines)) if lines[i].lstrip().startswith("[")),
        len(lines),
    )
    for key, value in keys.items():
        setting = f"{key} = {value!r}"
        found = [i for i in range(header + 1, end) if re.match(rf"^{key}\s*=", lines[i])]
        if found:
            lines[found[0]] = setting
        else:
            lines.insert(header + 1, setting)
            end += 1
    return "\n".join(lines) + "\n"


def output_matches(expected: tuple[str, ...], output: str) -> str | None:
    """None if every expected line appears in ``output``, in order; else the first missing.

    In an expected line ``...`` stands for anything; the rest must appear as written.
    """
    printed = output.splitlines()
    at = 0
    for line in expected:
        pattern = re.compile(".*?".join(re.escape(part) for part in line.strip().split("...")))
        while at < len(printed) and pattern.search(printed[at]) is None:
            at += 1
        if at == len(printed):
            return line
        at += 1
    return None

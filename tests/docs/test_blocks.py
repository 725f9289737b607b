"""Reading a page's fenced blocks: their kinds, test options, commands and expected output."""

from __future__ import annotations

import re
import time
import tomllib
from pathlib import Path

import pytest

from tests.docs.blocks import (
    COSIM,
    Block,
    Command,
    Kind,
    PageError,
    output_matches,
    read_page,
    shortened,
    strip_comment,
    with_study_keys,
)
from tests.docs.clone import Clone
from tests.docs.pages import DOCS, PAGES

PAGE = """\
# A page

```sh {test-duration-s="10"}
.venv/bin/cosim run warehouse-rows --out runs/rows \\
    --duration-s 300   # shortened to 10
```

```console
$ .venv/bin/cosim run warehouse-rows --set robots.cont=6
cosim: error: --set robots.cont: ... did you mean 'count'?
```

```toml title="my-hall.toml"
[robots]
count = 6
```

```text
results: runs/rows/
```
"""


def _page(tmp_path: Path, text: str) -> list[Block]:
    (tmp_path / "page.md").write_text(text)
    return read_page(tmp_path, "page.md")


def test_a_pages_blocks_are_read_with_their_kind_title_options_and_line(tmp_path):
    shell, console, file, output = _page(tmp_path, PAGE)
    kinds = [b.kind for b in (shell, console, file, output)]
    assert kinds == [Kind.SHELL, Kind.CONSOLE, Kind.FILE, Kind.OUTPUT]
    assert (shell.line, shell.title, shell.options) == (3, None, {"test-duration-s": "10"})
    assert shell.commands() == [
        Command(4, ".venv/bin/cosim run warehouse-rows --out runs/rows --duration-s 300")
    ]
    assert file.title == "my-hall.toml" and file.code == "[robots]\ncount = 6\n"
    assert output.name == "page.md:18 text"


def test_a_continued_command_is_one_command_without_its_comment():
    block = Block("p.md", 0, 1, "sh", "a \\\n  b   # why\n\n# a line of comment\nc '#kept'\n")
    assert block.commands() == [Command(2, "a b"), Command(6, "c '#kept'")]
    assert strip_comment('x "a # b" # c') == 'x "a # b" '


def test_a_console_commands_output_is_the_lines_after_it(tmp_path):
    (_, console, _, _) = _page(tmp_path, PAGE)
    (command,) = console.commands()
    assert command.text == ".venv/bin/cosim run warehouse-rows --set robots.cont=6"
    assert command.expected == ("cosim: error: --set robots.cont: ... did you mean 'count'?",)
    assert command.cosim_command == "run"


def test_output_before_any_command_of_a_console_block_is_refused():
    with pytest.raises(PageError, match=r"p.md:1 console: output before any"):
        Block("p.md", 0, 1, "console", "hello\n$ ls\n").commands()


@pytest.mark.parametrize(
    ("fence", "message"),
    [
        ('```sh {test-skipp="x"}', r"page.md:1: unknown fence option 'test-skipp'"),
        ('```sh test-skip="x"', r"page.md:1: test options go in braces"),
        ('```sh {title="a" why}', r"page.md:1: fence options .*expected key=\"value\" pairs"),
        ('```sh testskip="x"', r"page.md:1: unknown fence option 'testskip'"),
        ("```sh {test-skip=x}", r"page.md:1: fence options"),
    ],
)
def test_a_fence_option_the_tests_do_not_know_is_refused_naming_the_page_and_line(
    tmp_path, fence, message
):
    with pytest.raises(PageError, match=message):
        _page(tmp_path, f"{fence}\nls\n```\n")


def test_an_unclosed_fence_is_refused(tmp_path):
    with pytest.raises(PageError, match=r"page.md:2: a fence that is never closed"):
        _page(tmp_path, "text\n```sh\nls\n")


def test_the_duration_is_appended_to_runs_and_make_targets_and_nothing_else_changes():
    options = {"test-duration-s": "10"}
    run = Command(1, ".venv/bin/cosim run x --duration-s 300")
    assert shortened(run, options) == ".venv/bin/cosim run x --duration-s 300 --duration-s 10"
    assert shortened(Command(1, "make lab-real"), options) == "make lab-real ARGS='--duration-s 10'"
    check = Command(1, ".venv/bin/cosim check x --print > mine.toml")
    assert shortened(check, options) == check.text
    assert shortened(run, {}) == run.text
    with pytest.raises(PageError, match="cannot append"):
        shortened(Command(3, ".venv/bin/cosim run x | tee log"), options)


def test_a_shortened_study_file_has_its_study_keys_replaced_or_added():
    text = '# a study\n[study]\nname = "s"\nduration_s = 120\n\n[grid]\n"a.b" = [1, 2]\n'
    short = tomllib.loads(with_study_keys(text, {"duration_s": 5.0, "seeds": 1}))
    assert short["study"] == {"name": "s", "duration_s": 5.0, "seeds": 1}
    assert short["grid"] == {"a.b": [1, 2]}


def test_expected_output_must_appear_in_order_with_dots_for_anything():
    printed = "note: one\ncosim: error: --set a: [a] b = 1: expected 2\nlast\n"
    assert output_matches(("cosim: error: ... expected 2", "last"), printed) is None
    assert output_matches(("last", "note: one"), printed) == "note: one"
    assert output_matches(("expected 3",), printed) == "expected 3"


def test_every_page_reads_and_every_skip_says_why():
    for page in PAGES:
        for block in read_page(DOCS, page):
            assert block.skip is None or len(block.skip) > 10, block.name


def test_every_page_calls_cosim_as_the_environment_make_demo_made():
    for page in PAGES:
        for block in read_page(DOCS, page):
            for command in block.commands():
                if command.cosim_command is not None:
                    assert command.program == COSIM, f"{block.name}: {command.text}"
                assert not re.match(r"^(python|pip|pytest)\b", command.program), command.text


def test_a_page_that_speaks_of_the_paper_says_which():
    for page in (*PAGES, "index.md", "../README.md"):
        text = (DOCS / page).read_text()
        unnamed = re.search(r"\bthe\s+paper\b", text, re.I)
        assert unnamed is None, f"{page}: {text[unnamed.start() : unnamed.end() + 30]!r}"
        assert "paper" not in text or "VirTooS paper" in text, page


def test_a_clone_runs_its_own_cosim_and_knows_no_bare_cosim(tmp_path):
    clone = Clone(tmp_path / "cosim")
    assert clone.shell(".venv/bin/cosim scenarios").returncode == 0
    bare = clone.shell("cosim scenarios")
    assert bare.returncode == 127, bare.told()
    assert (clone.root / "studies").is_dir() and not (clone.root / "studies").is_symlink()


def test_a_command_that_does_not_end_is_stopped_with_what_it_started(tmp_path):
    clone = Clone(tmp_path / "cosim")
    marker = tmp_path / "still-running"
    ran = clone.shell(f"(sleep 1; touch {marker}) & sleep 30", timeout_s=0.3)
    assert ran.returncode != 0 and "no end within 0.3 s" in ran.stderr
    time.sleep(1.5)
    assert not marker.exists()  # the background child was stopped too

"""A generated page as the site shows it: rendered by Markdown with the site's extensions.

mkdocs renders every page with the ``markdown`` library and the ``markdown_extensions`` of
``mkdocs.yml``; rendering with the same here tells what a reader sees, without building
the site.
"""

from __future__ import annotations

import html
import re
from html.parser import HTMLParser
from typing import Any

import markdown
import yaml

from tests.conftest import REPO


def _extensions() -> tuple[list[str], dict[str, Any]]:
    config = yaml.safe_load((REPO / "mkdocs.yml").read_text())
    names: list[str] = []
    options: dict[str, Any] = {}
    for entry in config["markdown_extensions"]:
        if isinstance(entry, dict):
            (name, given), *_ = entry.items()
            names.append(name)
            options[name] = given or {}
        else:
            names.append(entry)
    return names, options


def render(page: str) -> str:
    """The HTML of a Markdown page, as mkdocs makes it."""
    names, options = _extensions()
    return markdown.markdown(page, extensions=names, extension_configs=options)


class _Cells(HTMLParser):
    """The text of every table cell (``td``), in order, by row, and every tag met."""

    def __init__(self) -> None:
        super().__init__(convert_charrefs=True)
        self.cells: list[str] = []
        self.rows: list[list[int]] = []
        self.tags: list[str] = []
        self._depth = 0

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        self.tags.append(tag)
        if tag == "tr":
            self.rows.append([])
        if tag == "td":
            self.rows[-1].append(len(self.cells))
            self.cells.append("")
            self._depth += 1

    def handle_endtag(self, tag: str) -> None:
        if tag == "td":
            self._depth -= 1

    def handle_data(self, data: str) -> None:
        if self._depth:
            self.cells[-1] += data


def cells(page: str) -> list[str]:
    """The text of every table cell of a page, as shown (markup gone, entities decoded)."""
    parser = _Cells()
    parser.feed(render(page))
    return [" ".join(c.split()) for c in parser.cells]


def rows(page: str) -> list[list[str]]:
    """The shown text of every table body row's cells, row by row."""
    parser = _Cells()
    parser.feed(render(page))
    found = [[" ".join(parser.cells[i].split()) for i in row] for row in parser.rows]
    return [row for row in found if row]


def tags(page: str) -> set[str]:
    """Every HTML tag the rendered page holds (``<robot>`` would be one)."""
    parser = _Cells()
    parser.feed(render(page))
    return set(parser.tags)


def shown(page: str) -> str:
    """All the text of a rendered page, markup gone, spaces squeezed."""
    inline = re.sub(r"</?(code|em|strong|a|span)\b[^>]*>", "", render(page))
    text = html.unescape(re.sub(r"<[^>]+>", " ", inline))
    return " ".join(text.split())


def as_shown(written: str) -> str:
    """What a reader sees of text written with code spans: the spans' text, spaces squeezed."""
    text = re.sub(r"(`+)(.+?)(?<!`)\1(?!`)", lambda m: m.group(2).strip(), written, flags=re.S)
    return " ".join(text.split())

"""The scenario key reference: every key of every registered section, from the dataclasses."""

from __future__ import annotations

import dataclasses
import inspect
from typing import Any, get_args, get_type_hints

from cosim.core.registry import group_named
from cosim.reference.escaping import cell, code, text
from cosim.scenario.fields import UNITS as UNITS  # the reference's unit column, re-exported
from cosim.scenario.fields import Bounds, describe, implicit_bounds, key_unit
from cosim.scenario.fields import unit_of as unit_of
from cosim.scenario.loader import toml_value
from cosim.scenario.model import section_classes, section_registry


def _expected(key: str, field: dataclasses.Field[Any], hint: Any) -> str:
    group_name = field.metadata.get("registry")
    if group_name is not None:
        group = group_named(group_name)
        names = group.installed().names()
        off = field.metadata.get("off")
        nothing = f", or {code(off)} (none at all)" if off is not None else ""
        listed = ", ".join(code(n) for n in names)
        return f"a registered {cell(group.words)}: {listed}{nothing}"
    said = describe(hint)
    bounds = implicit_bounds(key, field.metadata.get("bounds", Bounds())).describe()
    return cell(f"{said} {bounds}".strip())


def section_markdown(name: str, cls: type[Any], package: str) -> list[str]:
    """One section's heading, description and table of keys."""
    doc = inspect.cleandoc(cls.__doc__ or "")
    registered = f"*Registered by package {code(package)} ({text(cls.__module__)}).*"
    lines = [f"## {code(f'[{name}]')}", "", registered, ""]
    lines += [text(doc.replace("``", "`")), ""]
    lines += ["| key | default | expected | unit | meaning |", "|---|---|---|---|---|"]
    hints = get_type_hints(cls)
    nested: list[tuple[str, type[Any]]] = []
    for field in dataclasses.fields(cls):
        hint = hints[field.name]
        default = field.default if field.default is not dataclasses.MISSING else None
        item = _table_item(hint)
        if item is not None:
            nested.append((f"{name}.{field.name}", item))
            expected = f"a list of tables ({code(f'[[{name}.{field.name}]]')}, below)"
        else:
            expected = _expected(field.name, field, hint)
        shown = code(toml_value(default)) if default is not None else ""
        doc_text = field.metadata.get("doc", "")
        lines.append(
            f"| {code(field.name)} | {shown} | {expected} | {cell(key_unit(field))} "
            f"| {cell(doc_text)} |"
        )
    profiles = getattr(cls, "PROFILES", None)
    if profiles:
        lines += ["", f"Profiles (`{name}.profile` fills these keys; keys given win):", ""]
        for profile, values in profiles.items():
            shown = ", ".join(code(f"{k} = {toml_value(v)}") for k, v in values.items())
            lines.append(f"- {code(profile)}: {shown}")
    for table_name, item in nested:
        lines += ["", f"### {code(f'[[{table_name}]]')}", ""]
        lines += section_markdown(table_name, item, package)[4:]
    lines.append("")
    return lines


def _table_item(hint: Any) -> type[Any] | None:
    args: tuple[Any, ...] = get_args(hint)
    item = args[0] if len(args) == 2 and args[1] is Ellipsis else None
    return item if isinstance(item, type) and dataclasses.is_dataclass(item) else None


def keys_markdown() -> str:
    """The whole scenario key reference page."""
    registry = section_registry()
    lines = [
        "# Scenario keys",
        "",
        "Every key of every settings section registered by the installed packages, with its "
        "default, what it accepts and its unit: the one its name carries (`_m`, `_s`, "
        "`_mps`, `_dbm`, ...), or the one declared with `param(..., unit=...)` where a "
        "name cannot carry it; a number without a unit says what it is instead (`count`, "
        "`probability`, `id`, ...). A scenario file sets them as TOML "
        "(`[section]` then `key = value`); `--set section.key=value` and a study's "
        "`[grid]`/`[overrides]` address them as `section.key`. An unknown section or key, a "
        "value of the wrong type or out of bounds is refused in one line naming the file, "
        "the key, the value and what was expected. Keys ending in `_hz`, `_s` or `_ms` "
        "have implicit limits besides the declared ones (a rate of at least 0.001 Hz, at "
        "most 1 MHz; a time of at most 10⁹ s).",
        "",
        "This page is generated from the section dataclasses (`cosim/reference/keys_page.py`).",
        "",
    ]
    for name, cls in section_classes().items():
        lines += section_markdown(name, cls, registry.package(name))
    return "\n".join(lines) + "\n"

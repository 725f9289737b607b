"""Keys that choose a registered implementation: its own checks, and keys left doing nothing.

A key such as ``network.loss_model`` names an entry of a registry (``param(...,
registry="cosim.loss_models")``). The entries may declare, as class attributes:

- ``keys``: the keys of the same section only they read. Set to another value than its
  default while another entry is chosen, such a key would do nothing: it is refused,
  naming the entries that read it (a Bernoulli ``loss_prob`` with ``loss_model =
  "none"``);
- ``problems(section)``: a class method yielding :class:`~cosim.scenario.fields.Problem`
  for values of the section the entry cannot run with (a lognormal latency of 0 ms).

A section's ``problems()`` calls :func:`choice_problems` for each such key, so that no
section compares implementation names itself.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Iterator
from typing import Any

from cosim.core.registry import group_named
from cosim.scenario.fields import Problem


def choice_problems(section: Any, key: str) -> Iterator[Problem]:
    """The problems of the entry ``section.<key>`` chooses, and keys only others read.

    Args:
        section: a settings section (a dataclass instance).
        key: the key that names the entry; its field declares the registry.

    An unregistered name yields nothing here (the key's own check refuses it), nor does a
    plugin that cannot be loaded (the run that uses it says why). The key's ``off`` value
    (``param(..., off="none")``) chooses nothing: every entry's own keys are left unused.
    """
    fields = {f.name: f for f in dataclasses.fields(section)}
    registry = group_named(fields[key].metadata["registry"]).installed()
    chosen_name = getattr(section, key)
    off = chosen_name == fields[key].metadata.get("off")
    if chosen_name not in registry and not off:
        return
    entries = registry.load_all()
    chosen = entries.get(chosen_name)
    if chosen is None and not off:
        return
    own_check = getattr(chosen, "problems", None)
    if callable(own_check):
        yield from own_check(section)
    mine = set(getattr(chosen, "keys", ()))
    readers: dict[str, list[str]] = {}
    for name, entry in entries.items():
        for read in getattr(entry, "keys", ()):
            readers.setdefault(read, []).append(name)
    for read, names in readers.items():
        value = getattr(section, read)
        default = fields[read].default
        if read in mine or value == default:
            continue
        who = " or ".join(repr(n) for n in names)
        if default in ("", ()):
            yield Problem(read, value, f"no {read} unless {key} is {who}")
        else:
            shown = f"{default:g}" if isinstance(default, float) else repr(default)
            yield Problem(
                read, value, f"{shown} with {key} {chosen_name!r} (only {who} read {read})"
            )

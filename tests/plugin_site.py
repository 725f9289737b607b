"""A plugin package installed into a folder of its own, as pip would lay it out.

Tests that need a real distribution (its name and version found by ``importlib.metadata``,
its entry points loaded by another process: ``cosim`` on the command line, a study's
worker processes) write one with :func:`plugin_site` and put the folder on ``PYTHONPATH``.
"""

from __future__ import annotations

import os
from pathlib import Path

from tests.conftest import REPO


def plugin_site(
    root: Path, name: str, version: str, entry_points: str, modules: dict[str, str]
) -> dict[str, str]:
    """Install package ``name`` ``version`` into ``root``; the environment that sees it.

    Args:
        root: an empty folder (a site-packages of its own).
        name: the distribution and import package name.
        version: its version.
        entry_points: the text of ``entry_points.txt`` (``[cosim.adapters]`` ...).
        modules: module file name (``sensor.py``) -> source, inside the package.
    """
    info = root / f"{name}-{version}.dist-info"
    info.mkdir(parents=True)
    (info / "METADATA").write_text(f"Metadata-Version: 2.1\nName: {name}\nVersion: {version}\n")
    (info / "entry_points.txt").write_text(entry_points)
    package = root / name
    package.mkdir()
    (package / "__init__.py").write_text("")
    for file, source in modules.items():
        (package / file).write_text(source)
    return {**os.environ, "PYTHONPATH": os.pathsep.join([str(root), str(REPO)])}

"""Plugin packages installed for one test, as pip would: a ``*.dist-info`` folder and modules.

:func:`write_package` lays a distribution out in a folder (its ``METADATA``, its
``entry_points.txt``, its modules); :func:`on_path` puts the folder on ``sys.path`` of this
process while inside (cosim reads the installed packages again on the way in and out), and
:func:`env_with` gives the environment of a ``python -m cosim`` process that sees it.
"""

from __future__ import annotations

import contextlib
import importlib
import os
import sys
from collections.abc import Iterator, Mapping
from pathlib import Path

from cosim.core.plugins import rescan
from tests.conftest import REPO


def write_package(
    site: Path,
    name: str,
    version: str,
    entry_points: Mapping[str, Mapping[str, str]],
    modules: Mapping[str, str] | None = None,
) -> Path:
    """Lay out distribution ``name`` ``version`` in ``site``; return ``site``.

    Args:
        site: the folder (made if missing), as a ``site-packages``.
        name: the distribution's name (``clashkit``).
        version: its version (``0.1.0``).
        entry_points: group -> {registered name: ``module:attribute``}.
        modules: file path under ``site`` (``clashkit/greedy.py``) -> its source; the
            package folders' ``__init__.py`` are written when missing.
    """
    info = site / f"{name.replace('-', '_')}-{version}.dist-info"
    info.mkdir(parents=True)
    (info / "METADATA").write_text(f"Metadata-Version: 2.1\nName: {name}\nVersion: {version}\n")
    lines = []
    for group, names in entry_points.items():
        lines += [f"[{group}]", *(f"{n} = {target}" for n, target in names.items()), ""]
    (info / "entry_points.txt").write_text("\n".join(lines))
    for relative, source in (modules or {}).items():
        path = site / relative
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(source)
        for folder in Path(relative).parents:
            if folder != Path(".") and not (site / folder / "__init__.py").exists():
                (site / folder / "__init__.py").write_text("")
    return site


@contextlib.contextmanager
def on_path(site: Path) -> Iterator[None]:
    """While inside, the packages in ``site`` are installed in this process."""
    before = set(sys.modules)
    sys.path.insert(0, str(site))
    importlib.invalidate_caches()
    rescan()
    try:
        yield
    finally:
        sys.path.remove(str(site))
        for name in set(sys.modules) - before:  # the packages' modules, imported inside
            if str(site) in str(getattr(sys.modules[name], "__file__", None) or ""):
                del sys.modules[name]
        importlib.invalidate_caches()
        rescan()


def env_with(site: Path) -> dict[str, str]:
    """The environment of a ``python -m cosim`` process with ``site``'s packages installed."""
    return {**os.environ, "PYTHONPATH": os.pathsep.join([str(site), str(REPO)])}

"""Putting finished results in place so that none is lost and nothing else is touched.

Results are first written whole into a folder of their own *inside* the folder they are for
(``OUT/.cosim-partial-XXXXXXXX``, :func:`stage_in`): it is on the same file system as their
places, whatever ``OUT`` is (a symbolic link to another disk, a mount point, a folder in a
read-only one), so each file then takes its place by a rename (:func:`put_in_place`). Where
a rename cannot cross devices after all (``OUT/tables`` a link to another disk), the file is
copied beside its place and renamed there. No name outside the folder is used, so nothing
of the user's beside ``OUT`` is ever touched.

When the folder cannot take the results (full, read-only), they are written to a new folder
in the system's temporary folder instead (:func:`spare_folder`) and the error says where.
"""

from __future__ import annotations

import errno
import os
import re
import shutil
import tempfile
from collections.abc import Callable
from pathlib import Path

from cosim.core.errors import ExportError

STAGING_PREFIX = ".cosim-partial-"
"""The name of a staging folder or file begins so (then ``tempfile``'s random letters)."""
_STAGING = re.compile(re.escape(STAGING_PREFIX) + r"[a-z0-9_]+(?:\.[\w.-]+)?")
LAST_FILE = "summary.json"
"""Takes its place last: a folder with it holds the whole of the results."""


def stage_in(folder: Path) -> Path:
    """A new, empty staging folder inside ``folder`` (which must exist).

    Raises:
        OSError: ``folder`` cannot be written.
    """
    return Path(tempfile.mkdtemp(prefix=STAGING_PREFIX, dir=folder))


def is_staging(path: Path) -> bool:
    """Whether ``path`` is a staging folder or file cosim made (by its name; not a link)."""
    return bool(_STAGING.fullmatch(path.name)) and not path.is_symlink()


def stale_stagings(folder: Path) -> list[Path]:
    """The staging folders and files that cosim left in ``folder`` (a run killed outright)."""
    return sorted(p for p in folder.iterdir() if is_staging(p))


def put_in_place(stage: Path, target: Path) -> None:
    """Move every file of ``stage`` to the same place under ``target``, replacing files there.

    ``summary.json`` comes last. A file is renamed, or, where the rename cannot cross
    devices, copied beside its place and renamed there (a reader sees the old file or the
    new one, never half of one). ``stage`` is left with empty folders only.

    Raises:
        ExportError: a folder stands where a file goes, or a file where a folder goes
            (the rest stays in ``stage``).
        OSError: the file system refuses (the rest stays in ``stage``).
    """
    for entry in sorted(stage.iterdir(), key=lambda e: (e.name == LAST_FILE, e.name)):
        place = target / entry.name
        if entry.is_dir():
            if not (place.exists() or place.is_symlink()) and _renamed(entry, place):
                continue
            if place.exists() and not place.is_dir():
                raise ExportError(f"{place}: is a file where the results have a folder")
            place.mkdir(exist_ok=True)
            put_in_place(entry, place)
        elif place.is_dir():
            raise ExportError(f"{place}: is a folder where the results have a file")
        else:
            _move(entry, place)


def _renamed(folder: Path, place: Path) -> bool:
    """Rename a whole folder to a free place; False where that would cross devices."""
    try:
        os.rename(folder, place)
    except OSError as error:
        if error.errno != errno.EXDEV:
            raise
        return False
    return True


def _move(source: Path, place: Path) -> None:
    try:
        os.replace(source, place)
    except OSError as error:
        if error.errno != errno.EXDEV:
            raise
        replace_file(place, lambda beside: shutil.copyfile(source, beside))
        source.unlink()


def replace_file(path: Path, write: Callable[[Path], object]) -> None:
    """Write ``path`` anew through ``write(beside)``, a file beside it, then a rename.

    The file beside has a name of its own (:data:`STAGING_PREFIX`), so no file of the
    user's is overwritten on the way, and it is removed if the writing fails.

    Raises:
        OSError: the file system refuses (``path`` is then as it was).
    """
    handle, name = tempfile.mkstemp(prefix=STAGING_PREFIX, suffix=f".{path.name}", dir=path.parent)
    os.close(handle)
    beside = Path(name)
    try:
        write(beside)
        os.replace(beside, path)
    except BaseException:
        beside.unlink(missing_ok=True)
        raise


def spare_folder(name: str) -> Path:
    """A new folder in the system's temporary folder (``$TMPDIR``) for results with no home.

    Raises:
        OSError: none can be made.
    """
    return Path(tempfile.mkdtemp(prefix=f"cosim-{name}-"))


def discard(folder: Path | None) -> None:
    """Remove a staging or spare folder cosim made, with what it holds (best effort)."""
    if folder is not None:
        shutil.rmtree(folder, ignore_errors=True)


def reason(error: OSError) -> str:
    """An OS error in a few words (``No space left on device``)."""
    return error.strerror or str(error)


__all__ = [
    "STAGING_PREFIX",
    "discard",
    "is_staging",
    "put_in_place",
    "reason",
    "replace_file",
    "spare_folder",
    "stage_in",
    "stale_stagings",
]

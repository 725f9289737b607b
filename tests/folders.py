"""Places to write results that are not plain folders: another device, a read-only parent.

Each is real (a folder on another file system, a mount point inside a read-only mount, a
folder that root cannot write either); where this machine cannot make one, the test is
skipped saying why.
"""

from __future__ import annotations

import contextlib
import os
import subprocess
import tempfile
from collections.abc import Iterator
from pathlib import Path

import pytest

SHARED_MEMORY = Path("/dev/shm")
"""A tmpfs on most Linux machines: another device than the disk the tests run on."""


def _mount(*args: str) -> bool:
    return subprocess.run(["mount", *args], capture_output=True).returncode == 0


def _umount(where: Path) -> None:
    if subprocess.run(["umount", str(where)], capture_output=True).returncode:
        subprocess.run(["umount", "-l", str(where)], capture_output=True)


@contextlib.contextmanager
def another_device(near: Path) -> Iterator[Path]:
    """A new folder on another file system than ``near`` (removed afterwards).

    ``/dev/shm`` when it is one; else a tmpfs mounted in ``near`` (root only); else skip.
    """
    device = near.stat().st_dev
    shared = SHARED_MEMORY.is_dir() and os.access(SHARED_MEMORY, os.W_OK)
    if shared and SHARED_MEMORY.stat().st_dev != device:
        with tempfile.TemporaryDirectory(dir=SHARED_MEMORY) as folder:
            yield Path(folder)
        return
    mounted = near / "other-device"
    mounted.mkdir()
    if not _mount("-t", "tmpfs", "-o", "size=64m", "tmpfs", str(mounted)):
        pytest.skip(f"no second device: {SHARED_MEMORY} is on the same one and mount is refused")
    try:
        assert mounted.stat().st_dev != device
        yield mounted
    finally:
        _umount(mounted)


@contextlib.contextmanager
def read_only_parent(near: Path) -> Iterator[Path]:
    """A writable folder ``res`` inside a folder that cannot be written; yields ``res``.

    Not root: ``chmod 555`` on the parent. Root (whom permissions do not stop): a tmpfs
    mounted read-only holding a tmpfs mounted read-write at ``res``; skipped where mounting
    is refused.
    """
    parent = near / "read-only"
    parent.mkdir()
    out = parent / "res"
    if os.geteuid() != 0:
        out.mkdir()
        parent.chmod(0o555)
        try:
            yield out
        finally:
            parent.chmod(0o755)
        return
    if not _mount("-t", "tmpfs", "-o", "size=16m", "tmpfs", str(parent)):
        pytest.skip("running as root, whom chmod does not stop, and mount is refused")
    try:
        out.mkdir()
        if not _mount("-t", "tmpfs", "-o", "size=64m", "tmpfs", str(out)):
            pytest.skip("running as root, whom chmod does not stop, and mount is refused")
        try:
            if not _mount("-o", "remount,ro", str(parent)):
                pytest.skip("running as root and the parent cannot be remounted read-only")
            yield out
        finally:
            _umount(out)
    finally:
        _umount(parent)


def cannot_write(folder: Path) -> bool:
    """Whether a new file in ``folder`` is refused (the case is real)."""
    try:
        (folder / ".probe").write_text("x")
    except OSError:
        return True
    (folder / ".probe").unlink()
    return False


@contextlib.contextmanager
def tiny_disk(near: Path, size_kib: int) -> Iterator[Path | None]:
    """A tmpfs of ``size_kib`` KiB in a new folder of ``near``; None where mounting is refused."""
    where = near / f"disk-{size_kib}k"
    where.mkdir()
    if not _mount("-t", "tmpfs", "-o", f"size={size_kib}k", "tmpfs", str(where)):
        yield None
        return
    try:
        yield where
    finally:
        _umount(where)

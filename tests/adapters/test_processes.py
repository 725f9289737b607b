import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

from adapters import processes
from adapters.processes import die_with_parent
from tests.conftest import REPO

linux_only = pytest.mark.skipif(
    not sys.platform.startswith("linux"), reason="PR_SET_PDEATHSIG is Linux's"
)

PARENT = textwrap.dedent(
    """
    import subprocess, sys
    from adapters.processes import die_with_parent

    watched, signal_number, child = sys.argv[1] == "1", int(sys.argv[2]), sys.argv[3:]
    hook = (lambda: die_with_parent(signal_number)) if watched else None
    process = subprocess.Popen(child, preexec_fn=hook)
    print(process.pid, flush=True)
    process.wait()
    """
)
"""A parent that starts ``child`` (dying with it or not), says the child's pid and waits."""

CHILD = textwrap.dedent(
    """
    import pathlib, signal, sys, time

    said = pathlib.Path(sys.argv[1])
    signal.signal(signal.SIGTERM, lambda *_: (said.write_text("SIGTERM"), sys.exit(0)))
    said.with_suffix(".ready").write_text("")
    time.sleep(30)
    """
)
"""A child that writes which signal ended it (SIGTERM), after saying it is ready."""


def _alive(pid: int) -> bool:
    """Whether ``pid`` runs (a zombie waiting for its new parent to reap it has died)."""
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except (OSError, IndexError):
        return False
    return state not in ("Z", "X")


def _start(tmp_path: Path, watched: bool, sig: int) -> tuple[subprocess.Popen[str], int, Path]:
    """Start a parent whose child waits for 30 s; return the parent, the child's pid, its file."""
    said = tmp_path / "said.txt"
    child = [sys.executable, "-c", CHILD, str(said)]
    parent = subprocess.Popen(
        [sys.executable, "-c", PARENT, "1" if watched else "0", str(int(sig)), *child],
        cwd=REPO,
        stdout=subprocess.PIPE,
        text=True,
    )
    assert parent.stdout is not None
    pid = int(parent.stdout.readline())
    deadline = time.monotonic() + 10.0
    while not said.with_suffix(".ready").exists() and time.monotonic() < deadline:
        time.sleep(0.01)
    assert said.with_suffix(".ready").exists(), "the child never started"
    return parent, pid, said


def _kill_parent_and_wait(parent: subprocess.Popen[str], pid: int, within_s: float) -> bool:
    """SIGKILL the parent; whether the child is still running ``within_s`` later."""
    parent.kill()
    parent.wait()
    deadline = time.monotonic() + within_s
    while _alive(pid) and time.monotonic() < deadline:
        time.sleep(0.01)
    return _alive(pid)


@linux_only
def test_a_child_that_asked_dies_when_its_parent_is_killed_outright(tmp_path):
    parent, pid, _ = _start(tmp_path, watched=True, sig=signal.SIGKILL)
    assert not _kill_parent_and_wait(parent, pid, within_s=5.0)


@linux_only
def test_without_asking_the_child_outlives_its_killed_parent(tmp_path):
    parent, pid, _ = _start(tmp_path, watched=False, sig=signal.SIGKILL)
    try:
        assert _kill_parent_and_wait(parent, pid, within_s=0.3)
    finally:
        if _alive(pid):
            os.kill(pid, signal.SIGKILL)


@linux_only
def test_the_child_gets_the_signal_it_asked_for(tmp_path):
    parent, pid, said = _start(tmp_path, watched=True, sig=signal.SIGTERM)
    assert not _kill_parent_and_wait(parent, pid, within_s=5.0)
    assert said.read_text() == "SIGTERM"


@linux_only
def test_the_kernel_takes_the_request_on_linux():
    # asked in a child of its own: the test process must not die with pytest's parent
    done = subprocess.run(
        [sys.executable, "-c", "from adapters.processes import die_with_parent as d; print(d())"],
        cwd=REPO,
        capture_output=True,
        text=True,
        check=True,
    )
    assert done.stdout == "True\n"


def test_off_linux_nothing_is_asked_and_it_says_so(monkeypatch):
    monkeypatch.setattr(sys, "platform", "darwin")
    called = []
    monkeypatch.setattr(processes.ctypes, "CDLL", lambda *a, **k: called.append(a))
    assert die_with_parent() is False
    assert called == []


@linux_only
@pytest.mark.parametrize("error", [OSError("no libc"), AttributeError("prctl")])
def test_a_libc_without_prctl_is_a_refusal_not_an_error(monkeypatch, error):
    def missing(*_args, **_kwargs):
        raise error

    monkeypatch.setattr(processes.ctypes, "CDLL", missing)
    assert die_with_parent() is False


@linux_only
def test_a_refused_prctl_is_reported_as_false(monkeypatch):
    class Libc:
        def prctl(self, *args):
            assert args == (processes.PR_SET_PDEATHSIG, int(signal.SIGTERM), 0, 0, 0)
            return -1

    monkeypatch.setattr(processes.ctypes, "CDLL", lambda *a, **k: Libc())
    assert die_with_parent(signal.SIGTERM) is False

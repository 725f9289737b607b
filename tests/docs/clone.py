"""A folder laid out as a reader's clone of cosim after ``make demo``, to run a page in.

The reader runs a page's commands from the clone's folder, with the environment ``make
setup`` made in ``.venv``. Here the folder holds the repository's files (links to them; the
folders a page may change are copies: ``examples``, and ``studies`` whose files a shortened
study replaces) and a ``.venv`` of its own: a virtual environment that sees everything
installed in the repository's ``.venv`` (a ``.pth`` file adds it) and takes what a page
installs (``pip install -e fleet-battery``) for itself, so a page never changes the
environment the tests run in. Its ``pip.conf`` installs offline and without build isolation
(the environment's setuptools builds a page's package); ``.venv/bin/cosim`` is cosim's
command; ``.venv/.installed`` is the stamp ``make setup`` leaves, so ``make demo`` runs
without installing again. Commands run in bash with ``PATH`` cleared of any virtual
environment and any other ``cosim``: a page's ``cosim`` must be ``.venv/bin/cosim``, as a
fresh clone has it.
"""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import sys
import sysconfig
import time
from dataclasses import dataclass
from pathlib import Path

from tests.conftest import REPO

LEFT_OUT = frozenset({".venv", ".git", "runs", "site", "build", "examples", "studies"})
"""Top-level entries not linked: the environment, what runs write, and the copied folders."""
TIMEOUT_S = 600.0
"""The longest a command may take (s): a command that waits for ever fails, named."""
PIP_CONF = """\
[global]
no-index = true
disable-pip-version-check = true
# pip's "no-" options read false as "do it": no build isolation, setuptools from .venv
no-build-isolation = false
"""


@dataclass(frozen=True)
class Ran:
    """What a command did: its exit status and what it printed."""

    command: str
    returncode: int
    stdout: str
    stderr: str
    seconds: float

    @property
    def output(self) -> str:
        """Its standard output, then its standard error."""
        return self.stdout + self.stderr

    def told(self) -> str:
        """The command and the end of its output, for a failure's message."""
        tail = "\n".join(self.output.rstrip().splitlines()[-40:])
        said = f"exit status {self.returncode} after {self.seconds:.1f} s"
        return f"$ {self.command}\n({said})\n{tail}"


class Clone:
    """A reader's clone in ``root``: run its commands, its Python, write its files."""

    def __init__(self, root: Path) -> None:
        self.root = root
        root.mkdir(parents=True)
        for entry in sorted(REPO.iterdir()):
            if entry.name not in LEFT_OUT and not entry.name.endswith((".egg-info", "_cache")):
                (root / entry.name).symlink_to(entry)
        shutil.copytree(
            REPO / "examples", root / "examples", ignore=shutil.ignore_patterns("__pycache__")
        )
        (root / "studies").mkdir()
        for entry in sorted((REPO / "studies").iterdir()):
            (root / "studies" / entry.name).symlink_to(entry)
        self._environment()

    def _environment(self) -> None:
        venv = self.root / ".venv"
        subprocess.run(
            [sys.executable, "-m", "venv", "--without-pip", str(venv)], check=True, timeout=120
        )
        ours = sysconfig.get_paths()["purelib"]
        theirs = venv / Path(ours).relative_to(sys.prefix)
        (theirs / "_cosim_clone.pth").write_text(f"import site; site.addsitedir({ours!r})\n")
        (venv / "pip.conf").write_text(PIP_CONF)
        script = (Path(sys.prefix) / "bin" / "cosim").read_text().splitlines(keepends=True)
        cosim = venv / "bin" / "cosim"
        cosim.write_text(f"#!{venv / 'bin' / 'python'}\n" + "".join(script[1:]))
        cosim.chmod(0o755)
        (venv / ".installed").touch()

    @property
    def python(self) -> Path:
        """The clone's ``.venv/bin/python``."""
        return self.root / ".venv" / "bin" / "python"

    def env(self) -> dict[str, str]:
        """The reader's environment: no virtual environment active, no ``cosim`` on ``PATH``.

        A folder of ``PATH`` that holds a ``cosim`` (this environment's, another
        installation's, a pyenv shim) is left out: a page's bare ``cosim`` would run a cosim
        other than the clone's, and fails instead.
        """
        env = {k: v for k, v in os.environ.items() if k not in ("VIRTUAL_ENV", "PYTHONPATH")}
        venvs = {str(Path(sys.prefix) / "bin"), str(Path(sys.executable).parent)}
        path = [
            p
            for p in env.get("PATH", "").split(os.pathsep)
            if p and p not in venvs and not (Path(p) / "cosim").exists()
        ]
        env["PATH"] = os.pathsep.join(path)
        return env

    def shell(self, command: str, *, timeout_s: float = TIMEOUT_S) -> Ran:
        """Run ``command`` with bash in the clone's folder."""
        return self._run(["bash", "-c", command], command, timeout_s)

    def python_code(self, code: str, *, timeout_s: float = TIMEOUT_S) -> Ran:
        """Run ``code`` with the clone's Python in its folder (as ``python -c`` would)."""
        return self._run([str(self.python), "-c", code], "python <the page's code>", timeout_s)

    def _run(self, argv: list[str], shown: str, timeout_s: float) -> Ran:
        start = time.monotonic()
        # a session of its own: a command that hangs is stopped with every process it started
        with subprocess.Popen(
            argv, cwd=self.root, env=self.env(), stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
            stderr=subprocess.PIPE, text=True, start_new_session=True,
        ) as process:  # fmt: skip
            try:
                stdout, stderr = process.communicate(timeout=timeout_s)
            except subprocess.TimeoutExpired:
                os.killpg(process.pid, signal.SIGKILL)
                stdout, stderr = process.communicate()
                stderr += f"\n(stopped: no end within {timeout_s:g} s)"
        return Ran(shown, process.returncode, stdout, stderr, time.monotonic() - start)

    def write(self, relative: str, text: str) -> Path:
        """Write ``text`` to ``relative`` in the clone (a linked file is replaced, not followed)."""
        path = self.root / relative
        path.parent.mkdir(parents=True, exist_ok=True)
        if path.is_symlink():
            path.unlink()
        path.write_text(text)
        return path

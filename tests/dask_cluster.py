"""A real Dask scheduler and workers as separate processes on loopback, for study tests."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path


@dataclass
class DaskCluster:
    address: str
    workers: list[subprocess.Popen[bytes]]  # the `dask worker` commands (nanny processes)


@contextmanager
def dask_cluster(
    folder: Path, *, workers: int = 2, threads: int = 1, env: dict[str, str] | None = None
) -> Iterator[DaskCluster]:
    """Start a scheduler and ``workers`` worker processes of ``threads`` threads each.

    ``env`` adds to the processes' environment (a ``PYTHONPATH`` with plugins, say).
    """
    dask = str(Path(sys.executable).parent / "dask")
    scheduler_file = folder / "scheduler.json"
    env = {**os.environ, "DASK_DISTRIBUTED__WORKER__DAEMON": "False", **(env or {})}
    quiet = {"stdout": subprocess.DEVNULL, "stderr": subprocess.DEVNULL, "env": env}
    procs = [
        subprocess.Popen(
            [dask, "scheduler", "--host", "127.0.0.1", "--port", "0", "--no-dashboard",
             "--scheduler-file", str(scheduler_file)],
            **quiet,
        )
    ]  # fmt: skip
    try:
        deadline = time.monotonic() + 60
        while not scheduler_file.exists() and time.monotonic() < deadline:
            time.sleep(0.2)
        assert scheduler_file.exists(), "dask scheduler did not start"
        for _ in range(workers):
            procs.append(
                subprocess.Popen(
                    [dask, "worker", "--scheduler-file", str(scheduler_file), "--nworkers", "1",
                     "--nthreads", str(threads), "--no-dashboard", "--host", "127.0.0.1"],
                    **quiet,
                )
            )  # fmt: skip
        address = json.loads(scheduler_file.read_text())["address"]
        from distributed import Client

        with Client(address, timeout="30s") as client:
            client.wait_for_workers(workers, timeout=60)
        yield DaskCluster(address, procs[1:])
    finally:
        for proc in reversed(procs):
            proc.terminate()
        for proc in procs:
            try:
                proc.wait(timeout=20)
            except subprocess.TimeoutExpired:
                proc.kill()

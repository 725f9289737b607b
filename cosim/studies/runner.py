"""The study runner: plan the runs, execute them locally or on Dask, collect, report.

The study folder::

    results.parquet     one row per run (run_id, seed, every override, every metric, ...)
    plan.json           the runs of the study (checked when resuming)
    runs/<run_id>/      row.json, summary.json, scenario.toml[, tables/*.parquet]
    figures/, report.md

A run's folder appears at once, complete (written beside it, then renamed), so a study
killed at any moment leaves only finished runs behind; ``resume`` skips them and retries
runs that failed. Rows are identical whatever the executor and the worker count, except the
machine-dependent columns (:data:`~cosim.studies.worker.VOLATILE_METRICS`).
"""

from __future__ import annotations

import json
import os
import shutil
import sys
import time
from collections.abc import Iterator
from concurrent.futures import Future, ProcessPoolExecutor, as_completed
from concurrent.futures.process import BrokenProcessPool
from multiprocessing import get_context
from pathlib import Path
from typing import Protocol, TextIO

import pandas as pd

from cosim.core.errors import ConfigError, ExportError, WorkerError
from cosim.studies.spec import RunSpec, StudySpec
from cosim.studies.worker import Job, Outcome, failed, run_one


def _jobs(spec: StudySpec, runs: list[RunSpec]) -> list[Job]:
    return [
        Job(r.run_id, spec.scenario, r.seed, spec.duration_s, r.overrides, spec.tables)
        for r in runs
    ]


def _plan_text(spec: StudySpec) -> str:
    plan = [{"run_id": r.run_id, "seed": r.seed, "overrides": r.overrides} for r in spec.runs()]
    return json.dumps(
        {
            "study": spec.name,
            "scenario": spec.scenario,
            "duration_s": spec.duration_s,
            "runs": plan,
        },
        indent=1,
        sort_keys=True,
    )


def _prepare(spec: StudySpec, out: Path, resume: bool) -> set[str]:
    """Check the folder; return the run ids already done (resume only)."""
    plan = _plan_text(spec)
    plan_path = out / "plan.json"
    if out.exists() and any(out.iterdir()):
        if not resume:
            raise ExportError(
                f"{out}: folder is not empty; use --resume to continue the study "
                "there, or another --out"
            )
        if not plan_path.exists() or plan_path.read_text() != plan:
            raise ConfigError(
                f"{spec.path}: the study changed since {out} was started "
                "(different runs); use another --out"
            )
    (out / "runs").mkdir(parents=True, exist_ok=True)
    plan_path.write_text(plan)
    done = set()
    for folder in (out / "runs").iterdir():
        if folder.name.endswith(".partial"):
            shutil.rmtree(folder)  # a run cut short: it will run again
            continue
        row_path = folder / "row.json"
        if row_path.exists() and json.loads(row_path.read_text()).get("status") == "ok":
            done.add(folder.name)
    return done


def _write_run(out: Path, outcome: Outcome) -> None:
    run_id = outcome.row["run_id"]
    final = out / "runs" / run_id
    partial = out / "runs" / f"{run_id}.partial"
    if partial.exists():
        shutil.rmtree(partial)
    partial.mkdir(parents=True)
    if outcome.scenario_toml:
        (partial / "scenario.toml").write_text(outcome.scenario_toml)
    if outcome.summary:
        (partial / "summary.json").write_text(json.dumps(outcome.summary, indent=2) + "\n")
    if outcome.tables:
        (partial / "tables").mkdir()
        for name, data in outcome.tables.items():
            (partial / "tables" / f"{name}.parquet").write_bytes(data)
    (partial / "row.json").write_text(json.dumps(outcome.row, indent=1, default=str) + "\n")
    if final.exists():
        shutil.rmtree(final)  # an earlier failed attempt
    os.replace(partial, final)


BLAS_THREAD_VARIABLES = (
    "OMP_NUM_THREADS",
    "OPENBLAS_NUM_THREADS",
    "MKL_NUM_THREADS",
    "NUMBA_NUM_THREADS",
)


def _local(jobs: list[Job], workers: int) -> Iterator[Outcome]:
    if workers <= 1:
        for job in jobs:
            yield run_one(job)
        return
    # forkserver: workers fork from a clean server that has imported cosim once (fast to
    # start, and nothing inherited from this possibly multi-threaded process)
    context = get_context("forkserver")
    context.set_forkserver_preload(["cosim.studies.worker", "cosim.studies.warm"])
    # one BLAS thread per worker: the workers already fill the cores, and BLAS thread pools
    # fighting over them made two workers barely faster than one
    for name in BLAS_THREAD_VARIABLES:
        os.environ.setdefault(name, "1")
    with ProcessPoolExecutor(workers, mp_context=context) as pool:
        futures: list[Future[Outcome]] = [pool.submit(run_one, job) for job in jobs]
        try:
            for future in as_completed(futures):
                try:
                    outcome = future.result()
                except BrokenProcessPool:
                    raise WorkerError(
                        "a worker process died (killed, or out of memory) while running a run"
                    ) from None
                yield outcome
        finally:
            for future in futures:
                future.cancel()


def _dask(jobs: list[Job], scheduler: str) -> Iterator[Outcome]:
    from distributed import Client
    from distributed import as_completed as dask_completed

    # distributed's Client and as_completed carry no annotations
    try:
        client = Client(scheduler, timeout="20s")  # type: ignore[no-untyped-call]
    except OSError as error:
        raise ConfigError(
            f"--scheduler {scheduler}: cannot reach a Dask scheduler ({error})"
        ) from None
    try:
        keys = [f"cosim-{job.run_id}" for job in jobs]
        by_key = dict(zip(keys, jobs, strict=True))
        futures = client.map(run_one, jobs, key=keys, pure=False)
        for future in dask_completed(futures):  # type: ignore[no-untyped-call]
            try:
                outcome = future.result()
            except Exception as error:  # the run's worker was lost too often (KilledWorker)
                if client.status != "running":
                    raise WorkerError(
                        f"--scheduler {scheduler}: lost the Dask cluster ({error})"
                    ) from None
                outcome = failed(
                    by_key[future.key], f"worker lost: {type(error).__name__}: {error}", 0.0
                )
            # let the cluster forget the result: otherwise every run's tables stay in worker
            # memory until the study ends, and a lost worker's finished runs are recomputed
            future.release()
            yield outcome
    finally:
        client.close()  # type: ignore[no-untyped-call]


def _clock(seconds: float) -> str:
    """``1h02m03s``, ``2m03s`` or ``3s``."""
    whole = round(seconds)
    hours, rest = divmod(whole, 3600)
    minutes, secs = divmod(rest, 60)
    if hours:
        return f"{hours}h{minutes:02d}m{secs:02d}s"
    return f"{minutes}m{secs:02d}s" if minutes else f"{secs}s"


class StudyProgress(Protocol):
    """What :func:`run_study` reports to while it runs."""

    def begin(self, total: int, already_done: int) -> None:
        """The study has ``total`` runs, ``already_done`` of them finished earlier."""

    def __call__(self, outcome: Outcome) -> None:
        """One more run finished (``outcome.row["status"]`` tells how)."""


class Progress:
    """A progress bar with the time left; on a pipe, a plain line per tenth of the study.

    The time left is the mean wall time per run finished in this session times the runs
    still to do, so runs skipped on ``--resume`` count as done but not as fast.
    """

    WIDTH = 24

    def __init__(self, stream: TextIO | None = None) -> None:
        self.stream = stream if stream is not None else sys.stderr
        self.tty = self.stream.isatty()
        self.total = 0
        self.done = 0
        self.errors = 0
        self._session_done = 0
        self._start = time.perf_counter()
        self._last_tenth = -1

    def begin(self, total: int, already_done: int) -> None:
        """Start the clock; ``already_done`` runs finished before this session."""
        self.total = total
        self.done = already_done
        self._start = time.perf_counter()
        if already_done:
            self.stream.write(f"study: resuming, {already_done}/{total} runs already done\n")
            self.stream.flush()

    def __call__(self, outcome: Outcome) -> None:
        """Count one finished run and show where the study is."""
        self.done += 1
        self._session_done += 1
        self.errors += outcome.row.get("status") != "ok"
        elapsed = time.perf_counter() - self._start
        left = elapsed / self._session_done * (self.total - self.done)
        figures = (
            f"{self.done}/{self.total} runs, {self.errors} failed, "
            f"{_clock(elapsed)} elapsed, {_clock(left)} left"
        )
        if self.tty:
            filled = self.WIDTH * self.done // max(self.total, 1)
            bar = "#" * filled + "-" * (self.WIDTH - filled)
            self.stream.write(f"\rstudy [{bar}] {figures}\x1b[K")
            if self.done == self.total:
                self.stream.write("\n")
        else:
            tenth = self.done * 10 // max(self.total, 1)
            if tenth != self._last_tenth:
                self._last_tenth = tenth
                self.stream.write(f"study: {figures}\n")
        self.stream.flush()


def collect(spec: StudySpec, out: Path) -> pd.DataFrame:
    """Assemble results.parquet from the run folders, in plan order."""
    rows = []
    for run in spec.runs():
        row_path = out / "runs" / run.run_id / "row.json"
        if row_path.exists():
            rows.append(json.loads(row_path.read_text()))
    frame = pd.DataFrame(rows)
    if len(frame):
        frame.to_parquet(out / "results.parquet", index=False)
    return frame


def run_study(
    spec: StudySpec,
    out: str | Path,
    *,
    workers: int | None = None,
    scheduler: str | None = None,
    resume: bool = False,
    progress: StudyProgress | None = None,
    report: bool = True,
) -> pd.DataFrame:
    """Run a study and return its results (one row per run).

    Args:
        spec: from :func:`~cosim.studies.spec.load_study`.
        out: the study folder.
        workers: local processes (default: the machine's cores); ignored with ``scheduler``.
        scheduler: address of a Dask scheduler (``tcp://host:port``) to run on instead.
        resume: continue a study in ``out``: skip finished runs, retry failed ones.
        progress: told the run count, then called after every finished run.
        report: write figures and report.md when the study has a ``[report]`` section.

    Raises:
        ExportError: for a non-empty ``out`` without ``resume``.
        ConfigError: when resuming a different study, or an unreachable scheduler.
        WorkerError: a local worker process died, or the Dask cluster went away; the
            finished runs are kept (results.parquet included) for ``resume``.
    """
    out = Path(out)
    done = _prepare(spec, out, resume)
    runs = [r for r in spec.runs() if r.run_id not in done]
    jobs = _jobs(spec, runs)
    workers = workers or os.cpu_count() or 1
    if progress is not None:
        progress.begin(len(spec.runs()), len(done))
    outcomes = _dask(jobs, scheduler) if scheduler else _local(jobs, workers)
    try:
        for outcome in outcomes:
            _write_run(out, outcome)
            if progress is not None:
                progress(outcome)
    except WorkerError as error:
        finished = len(collect(spec, out))
        raise WorkerError(
            f"{spec.name}: {error}; the {finished} finished runs are kept in {out}: "
            "continue with --resume"
        ) from None
    results = collect(spec, out)
    if report and spec.report and len(results):
        from cosim.studies.reporting import report_study

        report_study(spec, out)
    return results


__all__ = ["Progress", "StudyProgress", "collect", "run_study"]

"""The study runner: plan the runs, execute them locally or on Dask, collect, report.

The study folder (:mod:`cosim.studies.folder`)::

    results.parquet     one row per run (run_id, seed, every override, every metric, ...)
    plan.json           the runs of the study and a fingerprint (checked when resuming)
    runs/<run_id>/      row.json, summary.json, scenario.toml[, tables/*.parquet]
    figures/, report.md

A run's folder appears at once, complete (written beside it, then renamed), so a study
killed at any moment leaves only finished runs behind; ``resume`` skips them and retries
runs that failed. Stopped by Ctrl-C or SIGTERM (:mod:`cosim.studies.lifeline`), a study
stops its workers, writes the finished runs' results and says so. Rows are identical
whatever the executor and the worker count, except the machine-dependent columns
(:data:`~cosim.studies.worker.VOLATILE_METRICS`).
"""

from __future__ import annotations

import os
import signal
import sys
from collections.abc import Callable, Iterator
from concurrent.futures import Future, ProcessPoolExecutor, as_completed
from concurrent.futures.process import BrokenProcessPool
from multiprocessing import get_context
from pathlib import Path
from typing import TYPE_CHECKING, Any

import pandas as pd

from cosim.core.errors import CosimError, ExportError, WorkerError
from cosim.studies.cluster import DEFAULT_TIMEOUT_S, check_scheduler, connect, dask_outcomes
from cosim.studies.fingerprint import job_of
from cosim.studies.folder import inspect
from cosim.studies.lifeline import STUDY_PID_VARIABLE, StudyStopped, bind_worker, signal_name
from cosim.studies.progress import Progress, StudyProgress
from cosim.studies.spec import StudySpec
from cosim.studies.worker import Job, Outcome, run_one
from cosim.studies.writing import collect, finished_rows, prepare, write_run

if TYPE_CHECKING:
    from cosim.runner.stopping import StopRequest

BLAS_THREAD_VARIABLES = (
    "OMP_NUM_THREADS",
    "OPENBLAS_NUM_THREADS",
    "MKL_NUM_THREADS",
    "NUMBA_NUM_THREADS",
)


def _local(jobs: list[Job], workers: int, stop: StopRequest | None) -> Iterator[Outcome]:
    if workers <= 1:  # in this process: a signal only asks its run to stop (see lifeline)
        for job in jobs:
            yield run_one(job, stop=stop)
        return
    # forkserver: workers fork from a clean server that has imported cosim once (fast to
    # start, and nothing inherited from this possibly multi-threaded process)
    context = get_context("forkserver")
    context.set_forkserver_preload(["cosim.studies.worker", "cosim.studies.warm"])
    # one BLAS thread per worker: the workers already fill the cores, and BLAS thread pools
    # fighting over them made two workers barely faster than one
    for name in BLAS_THREAD_VARIABLES:
        os.environ.setdefault(name, "1")
    os.environ[STUDY_PID_VARIABLE] = str(os.getpid())  # the fork server dies with us
    pool = ProcessPoolExecutor(
        workers, mp_context=context, initializer=bind_worker, initargs=(os.getpid(),)
    )
    completed = False
    try:
        futures: list[Future[Outcome]] = [pool.submit(run_one, job) for job in jobs]
        for future in as_completed(futures):
            try:
                outcome = future.result()
            except BrokenProcessPool:
                raise WorkerError(
                    "a worker process died (killed, or out of memory) while running a run"
                ) from None
            yield outcome
        completed = True
    finally:
        if not completed:  # stopped, or the folder failed: the runs under way are lost anyway
            _kill_workers(pool)
        pool.shutdown(wait=True, cancel_futures=True)


def _kill_workers(pool: ProcessPoolExecutor) -> None:
    """Stop a pool now: queued runs cancelled, the runs under way killed."""
    # taken before shutdown, which forgets them: killed after it, the workers would finish
    # their runs first (and the interpreter's exit would wait for them)
    processes: dict[int, Any] = dict(getattr(pool, "_processes", None) or {})
    pool.shutdown(wait=False, cancel_futures=True)
    for process in processes.values():
        process.kill()


def _notify(line: str) -> None:
    sys.stderr.write(f"study: {line}\n")
    sys.stderr.flush()


def run_study(
    spec: StudySpec,
    out: str | Path,
    *,
    workers: int | None = None,
    scheduler: str | None = None,
    scheduler_timeout_s: float = DEFAULT_TIMEOUT_S,
    resume: bool = False,
    progress: StudyProgress | None = None,
    report: bool = True,
    notify: Callable[[str], None] = _notify,
    stop: StopRequest | None = None,
) -> pd.DataFrame:
    """Run a study and return its results (one row per run).

    Args:
        spec: from :func:`~cosim.studies.validate.load_study`.
        out: the study folder.
        workers: local processes (default: the machine's cores); ignored with ``scheduler``.
        scheduler: address of a Dask scheduler (``tcp://host:port``) to run on instead.
        scheduler_timeout_s: how long to wait for the scheduler to answer (s).
        resume: continue a study in ``out``: skip finished runs, retry failed ones.
        progress: told the run count, then called after every finished run.
        report: write figures and report.md when the study has a ``[report]`` section.
        notify: told, a line each, what resuming found (a plan rebuilt, runs run again)
            and the runs the report leaves out of a figure.
        stop: the stop request of :func:`~cosim.studies.lifeline.stop_on_signals`: a run in
            this process (one worker) takes a signal as a request to stop at its next event
            boundary, then the study stops.

    Raises:
        ExportError: for a non-empty ``out`` without ``resume``, or a folder that cannot
            be written (read-only, full): the finished runs are kept for ``resume``.
        ConfigError: when resuming a different study (or the same one over a changed
            scenario), or for a bad or unreachable scheduler.
        WorkerError: a local worker process died, or the Dask cluster went away; the
            finished runs are kept (results.parquet included) for ``resume``.
        StudyStopped: Ctrl-C or SIGTERM (with :func:`~cosim.studies.lifeline.stop_on_signals`)
            stopped the study; the finished runs are kept for ``resume``.
    """
    out = Path(out)
    if scheduler:
        check_scheduler(scheduler)
    state = inspect(spec, out, resume=resume)
    for line in state.notes:
        notify(line)
    jobs = [job_of(spec, r) for r in spec.runs() if r.run_id not in state.done]
    client = connect(scheduler, scheduler_timeout_s) if scheduler else None
    try:
        prepare(out, state)
        if progress is not None:
            progress.begin(len(spec.runs()), len(state.done))
        if client is not None:
            outcomes = dask_outcomes(client, jobs, scheduler or "")
        else:
            outcomes = _local(jobs, workers or os.cpu_count() or 1, stop)
        _write_outcomes(spec, out, outcomes, progress)
    finally:
        if client is not None:
            client.close()
    try:
        results = collect(spec, out)
    except ExportError as error:  # every run is written: --resume only collects them
        raise ExportError(_kept_message(spec, out, error, len(finished_rows(spec, out)))) from None
    if report and spec.report and len(results):
        from cosim.studies.reporting import report_study

        report_study(spec, out, notify=notify)
    return results


def _write_outcomes(
    spec: StudySpec, out: Path, outcomes: Iterator[Outcome], progress: StudyProgress | None
) -> None:
    """Write each run as it finishes; on a failure or a stop, keep what finished."""
    try:
        for outcome in outcomes:
            write_run(out, outcome)
            if progress is not None:
                progress(outcome)
    except (WorkerError, ExportError) as error:
        _close(outcomes)
        raise type(error)(_kept_message(spec, out, error, _keep(spec, out))) from None
    except KeyboardInterrupt as stop:
        _close(outcomes)
        signum = getattr(stop, "signum", signal.SIGINT)
        kept = _keep(spec, out)
        raise StudyStopped(
            signum,
            f"{spec.name}: stopped by {signal_name(signum)}; the {kept} finished runs are "
            f"kept in {out}: continue with --resume",
        ) from None
    finally:
        _close(outcomes)


def _kept_message(spec: StudySpec, out: Path, error: CosimError, kept: int) -> str:
    """The line for a study cut short by ``error``: what happened, what is kept, what next."""
    return (
        f"{spec.name}: {error}; the {kept} finished runs are kept in {out}: "
        + ("free space or fix the folder, then " if isinstance(error, ExportError) else "")
        + "continue with --resume"
    )


def _close(outcomes: Iterator[Outcome]) -> None:
    close = getattr(outcomes, "close", None)
    if close is not None:
        close()


def _keep(spec: StudySpec, out: Path) -> int:
    """Write results.parquet of the finished runs if the folder lets us; their number."""
    try:
        return len(collect(spec, out))
    except CosimError:
        return len(finished_rows(spec, out))


__all__ = ["Progress", "StudyProgress", "collect", "run_study"]

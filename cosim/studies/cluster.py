"""Running a study's runs on a Dask cluster: the scheduler's address, the connection, the runs.

The address is checked before anything starts (``tcp://HOST:PORT``, or the other schemes
Dask speaks); a scheduler that does not answer in time, or something else answering at its
address (its dashboard, a proxy), is one line naming the address.
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

from cosim.core.errors import ConfigError, WorkerError
from cosim.studies.worker import Job, Outcome, failed, run_one

SCHEMES = ("tcp", "tls", "ws", "wss", "ucx")
"""Dask's network address schemes (``inproc`` is in-process only)."""
DEFAULT_TIMEOUT_S = 20.0
"""How long to wait for a scheduler to answer (s)."""
SHOWN_CHARS = 200


def _bad_address(address: str) -> ConfigError:
    return ConfigError(
        f"--scheduler {address!r}: expected a Dask scheduler address SCHEME://HOST:PORT, "
        f"e.g. tcp://10.0.0.5:8786 (schemes {', '.join(SCHEMES)}; port 1-65535)"
    )


def check_scheduler(address: str) -> None:
    """Refuse an address Dask could not connect to, before anything starts.

    Raises:
        ConfigError: naming the address and the form expected.
    """
    scheme, separator, rest = address.partition("://")
    host, colon, port = rest.rpartition(":")
    if host.startswith("[") and host.endswith("]"):  # an IPv6 literal
        host = host[1:-1]
    if (
        not separator
        or scheme not in SCHEMES
        or not colon
        or not host
        or not host.isprintable()
        or any(c in host for c in "/@?# ")
        or not (port.isascii() and port.isdigit())
        or not 1 <= int(port) <= 65535
    ):
        raise _bad_address(address)


def _one_line(error: BaseException) -> str:
    text = " ".join(f"{type(error).__name__}: {error}".split())
    return text if len(text) <= SHOWN_CHARS else text[: SHOWN_CHARS - 3] + "..."


def connect(address: str, timeout_s: float) -> Any:
    """A ``distributed.Client`` of the scheduler at ``address``.

    Raises:
        ConfigError: nothing answered within ``timeout_s``, or what answered is not a Dask
            scheduler.
    """
    try:
        return _client_class()(address, timeout=f"{timeout_s}s", set_as_default=False)
    except (OSError, TimeoutError) as error:
        raise ConfigError(
            f"--scheduler {address}: no Dask scheduler answered within {timeout_s:g} s "
            f"({_one_line(error)})"
        ) from None
    except Exception as error:  # something else answers there: it spoke garbage to Dask
        raise ConfigError(
            f"--scheduler {address}: what answers there is not a Dask scheduler "
            f"({_one_line(error)}); expected the scheduler's address (port 8786 by default), "
            "not its dashboard's"
        ) from None


def _client_class() -> Any:
    """``distributed.Client``, made to fail quietly when it cannot connect.

    A Client that fails to start keeps a connection that is broken or half-open; when it is
    garbage-collected it closes itself, waits on that connection for twice its timeout and
    prints "Exception ignored in ... TimeoutError" after the study's one line. Marked closed
    when its start fails, it has nothing to wait for.
    """
    from distributed import Client

    # distributed's Client carries no annotations
    class QuietClient(Client):
        def start(self, **kwargs: Any) -> None:
            try:
                super().start(**kwargs)  # type: ignore[no-untyped-call]
            except BaseException:
                self.status = "closed"
                self._loop_runner.stop()  # type: ignore[no-untyped-call]
                raise

    return QuietClient


def dask_outcomes(client: Any, jobs: list[Job], address: str) -> Iterator[Outcome]:
    """Run the jobs on the cluster; each outcome as it finishes.

    Raises:
        WorkerError: the cluster went away.
    """
    from distributed import as_completed

    keys = [f"cosim-{job.run_id}" for job in jobs]
    by_key = dict(zip(keys, jobs, strict=True))
    futures = client.map(run_one, jobs, key=keys, pure=False)
    for future in as_completed(futures, loop=client.loop):  # type: ignore[no-untyped-call]
        try:
            outcome = future.result()
        except Exception as error:  # the run's worker was lost too often (KilledWorker)
            if client.status != "running":
                raise WorkerError(
                    f"--scheduler {address}: lost the Dask cluster ({_one_line(error)})"
                ) from None
            outcome = failed(by_key[future.key], f"worker lost: {_one_line(error)}", 0.0)
        # let the cluster forget the result: otherwise every run's tables stay in worker
        # memory until the study ends, and a lost worker's finished runs are recomputed
        future.release()
        yield outcome

"""The Dask scheduler's address and connection (cosim.studies.cluster): one line, in time."""

import socket
import subprocess
import sys
import threading
import time
from collections.abc import Iterator

import pytest

from cosim.core.errors import ConfigError
from cosim.studies.cluster import check_scheduler
from tests.conftest import cosim_main
from tests.cosim.studies.small import small_study

NOT_ADDRESSES = ["notaurl", "tcp://", "tcp://host", "tcp://:8786", "http://h:8786", "tcp://h:0"]
NOT_ADDRESSES += ["tcp://h:65536", "tcp://h:port", "tcp://a/b:1", "tcp://u@h:1", "tcp://h:-1"]
NOT_ADDRESSES += ["tcp://h:١٢", "inproc://x:1"]


@pytest.mark.parametrize("address", NOT_ADDRESSES)
def test_an_address_dask_cannot_connect_to_is_refused_naming_the_flag(address):
    with pytest.raises(ConfigError) as refused:
        check_scheduler(address)
    message = str(refused.value)
    assert message.startswith(f"--scheduler {address!r}: expected a Dask scheduler address")
    assert "\n" not in message


@pytest.mark.parametrize(
    "address", ["tcp://10.0.0.5:8786", "tls://sched.example:8786", "tcp://[::1]:8786", "ws://h:1"]
)
def test_a_dask_address_passes_the_check(address):
    check_scheduler(address)


@pytest.mark.slow
def test_a_study_with_a_scheduler_that_is_no_address_exits_2_before_anything_starts(tmp_path):
    path = small_study(tmp_path)
    done = cosim_main("study", str(path), "--out", str(tmp_path / "out"), "--scheduler", "notaurl")
    assert done.returncode == 2, done.stdout
    assert done.stderr.startswith("cosim: error: --scheduler 'notaurl': expected a Dask scheduler")
    assert done.stderr.count("\n") == 1
    assert not (tmp_path / "out").exists()


@pytest.mark.slow
def test_a_scheduler_nobody_answers_at_exits_2_in_one_line_after_the_timeout(tmp_path):
    path = small_study(tmp_path)
    start = time.monotonic()
    done = cosim_main(
        "study",
        str(path),
        "--out",
        str(tmp_path / "out"),
        "--scheduler",
        "tcp://127.0.0.1:1",
        "--scheduler-timeout-s",
        "1",
    )
    took = time.monotonic() - start
    assert done.returncode == 2, done.stdout
    assert done.stderr.startswith(
        "cosim: error: --scheduler tcp://127.0.0.1:1: no Dask scheduler answered within 1 s"
    ), done.stderr
    assert done.stderr.count("\n") == 1
    assert took < 15, f"took {took:.1f} s for a 1 s timeout"
    assert not (tmp_path / "out").exists()


@pytest.fixture
def not_dask() -> Iterator[int]:
    """A TCP port on loopback where something answers, but not Dask (a web server's 404)."""
    server = socket.create_server(("127.0.0.1", 0))
    server.settimeout(0.2)
    stop = threading.Event()

    def serve() -> None:
        while not stop.is_set():
            try:
                conn, _ = server.accept()
            except TimeoutError:
                continue
            with conn:
                try:
                    conn.settimeout(1.0)
                    conn.recv(1024)
                    conn.sendall(b"HTTP/1.1 404 Not Found\r\nContent-Length: 0\r\n\r\n" * 4)
                except OSError:
                    pass

    thread = threading.Thread(target=serve, daemon=True)
    thread.start()
    yield server.getsockname()[1]
    stop.set()
    thread.join()
    server.close()


@pytest.mark.slow
def test_a_scheduler_address_where_something_else_answers_is_one_line_and_quick(tmp_path, not_dask):
    # a process of its own: the half-started client used to be collected at the
    # interpreter's exit, wait twice the timeout there and print "Exception ignored in"
    address = f"tcp://127.0.0.1:{not_dask}"
    path = small_study(tmp_path)
    command = [sys.executable, "-m", "cosim", "study", str(path), "--out", str(tmp_path / "out")]
    done = subprocess.run(
        [*command, "--scheduler", address, "--scheduler-timeout-s", "5"],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode == 2, done.stdout
    assert done.stderr.startswith(f"cosim: error: --scheduler {address}: what answers there is")
    assert "expected the scheduler's address" in done.stderr
    assert done.stderr.count("\n") == 1, done.stderr
    assert not (tmp_path / "out").exists()

"""`cosim run` never hangs, lies or loses what ran: bad flags, bad files, full disks, signals."""

import contextlib
import errno
import gc
import io
import json
import os
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from unittest import mock

import pandas as pd
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cosim.cli.args import build_parser
from cosim.core.errors import ExportError
from cosim.core.recorder import MESSAGES
from cosim.runner.runfolder import RUN_FORMAT
from cosim.runner.staging import STAGING_PREFIX
from cosim.scenario.fields import key_bounds
from cosim.scenario.sections import ScenarioSection
from tests.conftest import REPO, cosim_main

SMALL = [
    *("--set", "world.size_m=[12.0, 12.0]"),
    *("--set", "world.shelf_count=4"),
    *("--set", "robots.count=3"),
    *("--set", "lidar.beams=90"),
    *("--set", "robots.driver=waypoints"),
]
"""A 12 m hall, 3 robots driving waypoints: hundreds of times faster than real time."""


def _one_line(done):
    assert done.returncode == 2, done.stderr
    assert done.stderr.count("\n") == 1 and "Traceback" not in done.stderr, done.stderr
    return done.stderr


@pytest.mark.parametrize("value", ["1e30", "inf", "-inf", "nan", "0", "-1", "1e-7", "10000001"])
def test_a_duration_flag_outside_the_keys_bounds_is_refused_as_the_key_is(value, tmp_path):
    said = _one_line(cosim_main("run", "warehouse-random", f"--duration-s={value}", cwd=tmp_path))
    bounds = key_bounds(ScenarioSection, "duration_s").describe()
    assert f"argument --duration-s: {float(value):g} is not a duration {bounds} s" in said
    key = cosim_main("check", "warehouse-random", "--set", f"scenario.duration_s={value}")
    if float(value) == float(value) and abs(float(value)) != float("inf"):  # TOML has no nan
        assert bounds in _one_line(key)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("host", ["999.1.1.1", "1.2.3", "", "a b", "-bad", "x" * 254, "a..b"])
def test_a_live_host_that_is_no_address_is_blamed_on_live_host(host, tmp_path):
    said = _one_line(cosim_main("run", "warehouse-random", "--live", f"--live-host={host}"))
    assert f"argument --live-host: {host!r} is not an address; expected an IPv4" in said
    assert "--live-port" not in said


@pytest.mark.parametrize(
    "host", ["127.0.0.1", "0.0.0.0", "::1", "localhost", "robot-3.lab.example", "fe80::1%eth0"]
)
def test_addresses_and_host_names_are_taken_as_live_hosts(host):
    assert build_parser().parse_args(["run", "x", "--live-host", host]).live_host == host


def test_a_live_host_of_another_machine_is_refused_before_anything_is_written(tmp_path):
    # 192.0.2.1 (TEST-NET-1, RFC 5737) is never an address of this machine
    said = _one_line(
        cosim_main("run", "warehouse-random", "--live", "--live-host", "192.0.2.1", cwd=tmp_path)
    )
    assert said.startswith("cosim: error: --live-host '192.0.2.1': cannot listen on 192.0.2.1")
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("name", ["../escape", "../../tmp/x", "a/b", ".."])
def test_a_scenario_name_that_would_leave_runs_is_refused_and_nothing_is_written(name, tmp_path):
    (tmp_path / "s.toml").write_text(f'[scenario]\nname = "{name}"\nduration_s = 1.0\n')
    said = _one_line(cosim_main("run", "s.toml", cwd=tmp_path))
    assert f"s.toml: [scenario] name = {name!r}: expected one folder name" in said
    assert [p.name for p in tmp_path.iterdir()] == ["s.toml"]


def test_a_scenario_nested_thousands_deep_is_one_line_naming_the_file(tmp_path):
    (tmp_path / "deep.toml").write_text("a = " + "[" * 1500 + "]" * 1500 + "\n")
    said = _one_line(cosim_main("run", "deep.toml", cwd=tmp_path))
    assert said == "cosim: error: deep.toml: tables or arrays nested deeper than 100 levels; " + (
        "expected at most 100 (a scenario needs 4)\n"
    )


@pytest.mark.parametrize("bag", ["mcap", "none"])
@pytest.mark.parametrize(
    ("out", "fragment"),
    [
        ("taken", "taken: exists and is not a folder"),
        ("taken/run", "taken/run"),
        ("/proc/cosim-run", "/proc/cosim-run"),
    ],
)
def test_an_out_where_a_file_stands_is_one_line_before_the_run(bag, out, fragment, tmp_path):
    (tmp_path / "taken").write_text("mine")
    done = cosim_main("run", "warehouse-random", "--out", out, "--bag", bag, *SMALL, cwd=tmp_path)
    assert fragment in _one_line(done)
    assert (tmp_path / "taken").read_text() == "mine"


@contextlib.contextmanager
def _full_disk(folder: Path, size: str):
    """A tmpfs of ``size`` on ``folder``; where mounting is refused, writes fail with ENOSPC."""
    folder.mkdir()
    mounted = subprocess.run(
        ["mount", "-t", "tmpfs", "-o", f"size={size}", "tmpfs", str(folder)], capture_output=True
    )
    if mounted.returncode == 0:
        try:
            yield folder
        finally:
            gc.collect()  # a file the run left open would keep the mount busy
            unmounted = subprocess.run(["umount", str(folder)], capture_output=True, text=True)
            if unmounted.returncode != 0:
                subprocess.run(["umount", "-l", str(folder)], check=True)  # leave no mount
                pytest.fail(f"the run left a file open on the full disk: {unmounted.stderr}")
        return
    full = OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
    unfinished = ExportError(f"{folder}/run/bag: cannot finish the bag ({full})")
    with (
        mock.patch("pandas.DataFrame.to_parquet", side_effect=full),
        mock.patch("cosim.recording.bag.BagSink.close", side_effect=unfinished),
    ):
        yield folder


@pytest.mark.slow
@pytest.mark.parametrize(("bag", "size"), [("mcap", "64k"), ("sqlite3", "64k"), ("none", "12k")])
def test_a_full_disk_is_one_line_leaves_nothing_half_written_and_keeps_the_results_elsewhere(
    bag, size, tmp_path, monkeypatch
):
    spare = tmp_path / "spare"  # the system's temporary folder, for this test
    spare.mkdir()
    monkeypatch.setattr(tempfile, "tempdir", str(spare))
    with _full_disk(tmp_path / "disk", size) as disk:
        done = cosim_main(
            "run", "warehouse-random", "--duration-s", "20", "--bag", bag, "--out",
            str(disk / "run"), *SMALL,
        )  # fmt: skip
        said = _one_line(done)
        assert "No space left on device" in said or "disk is full" in said
        assert said.startswith(f"cosim: error: {disk / 'run'}")
        assert not (disk / "run.partial").exists()
        assert not (disk / "run" / "summary.json").exists()
        assert not [p for p in (disk / "run").iterdir() if p.name.startswith(STAGING_PREFIX)]
    kept = list(spare.iterdir())
    if not kept:  # no small disk could be mounted: the stand-in refuses every table anywhere
        assert said.endswith("no copy could be kept\n")
        return
    (where,) = kept
    assert said.endswith(f"they are kept in {where}/ instead\n")
    summary = json.loads((where / "summary.json").read_text())
    assert summary["format"] == RUN_FORMAT and summary["sim_time_s"] > 0
    assert len(pd.read_parquet(where / "tables" / "poses.parquet")) > 0


@pytest.mark.slow
def test_force_replaces_the_earlier_run_and_keeps_the_users_files(tmp_path):
    out = tmp_path / "run"
    args = ("run", "warehouse-random", "--duration-s", "1", "--out", str(out), "--quiet", *SMALL)
    assert cosim_main(*args, "--set", "mapping.enabled=true").returncode == 0
    assert (out / "tables" / "map_quality.parquet").exists()
    (out / "tables" / "mine.parquet").write_text("mine")
    (out / "maps" / "office.yaml").write_text("mine")
    done = cosim_main(*args, "--force")
    assert done.returncode == 0, done.stderr
    assert not (out / "tables" / "map_quality.parquet").exists()  # not this run's: removed
    assert (out / "tables" / "mine.parquet").read_text() == "mine"
    assert [p.name for p in (out / "maps").iterdir()] == ["office.yaml"]
    (out / "bag" / "notes.txt").write_text("mine")
    said = _one_line(cosim_main(*args, "--force"))
    assert f"{out}/bag: holds 'notes.txt', which no run writes" in said
    assert (out / "bag" / "metadata.yaml").exists() and (out / "summary.json").exists()


def _cosim_run(out: Path, *extra: str) -> subprocess.Popen[str]:
    """``python -m cosim run`` of a long run into ``out``, with Ctrl-C and SIGHUP at their
    defaults, as from a terminal (the tests may run under ``nohup``, which ignores SIGHUP)."""
    return subprocess.Popen(
        [sys.executable, "-m", "cosim", "run", "warehouse-random", "--duration-s", "1e6",
         "--out", str(out), *SMALL, *extra],
        cwd=REPO, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
        preexec_fn=_terminal_signals,
    )  # fmt: skip


def _terminal_signals() -> None:
    for sig in (signal.SIGINT, signal.SIGHUP):
        signal.signal(sig, signal.SIG_DFL)


def _wait_until_running(process: subprocess.Popen[str], bag: Path) -> None:
    """Until the bag has its first chunk (the kernel runs), at most 60 s."""
    deadline = time.monotonic() + 60
    mcap = bag / "bag.mcap"
    while not (mcap.exists() and mcap.stat().st_size > 64_000):
        assert process.poll() is None, process.communicate()
        assert time.monotonic() < deadline, "the run did not start in 60 s"
        time.sleep(0.05)


@pytest.mark.slow
@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM, signal.SIGHUP], ids=str)
def test_a_signal_mid_run_keeps_the_bag_the_tables_and_a_summary_that_says_so(sig, tmp_path):
    out = tmp_path / "run"
    process = _cosim_run(out)
    try:
        _wait_until_running(process, out / "bag")
        process.send_signal(sig)
        _stdout, stderr = process.communicate(timeout=60)
    finally:
        process.kill()
    assert process.returncode == 128 + sig
    name = signal.Signals(sig).name
    assert stderr.count("\n") == 1 and "Traceback" not in stderr, stderr
    assert stderr.startswith(f"cosim: stopped by {name} at ")
    assert f"of 1e+06 s simulated; the results so far are in {out}/" in stderr
    assert (out / "bag" / "metadata.yaml").is_file()
    info = cosim_main("bag", "info", str(out / "bag"))
    assert info.returncode == 0 and "messages:" in info.stdout
    summary = json.loads((out / "summary.json").read_text())
    assert summary["stopped"] == name and summary["planned_duration_s"] == 1e6
    reached = summary["sim_time_s"]
    assert 0 < reached < 1e6
    poses = pd.read_parquet(out / "tables" / "poses.parquet")
    assert reached - 0.1 - 1e-9 <= poses.t_s.max() <= reached  # 4.2 - 0.1 > 4.1 in floats
    assert len(pd.read_parquet(out / "tables" / f"{MESSAGES.name}.parquet")) > 0


def _children(pid: int) -> list[int]:
    found = []
    for entry in Path("/proc").iterdir():
        with contextlib.suppress(OSError, IndexError):
            if entry.name.isdigit() and (entry / "stat").read_text().split(") ")[1].split()[1] == (
                str(pid)
            ):
                found.append(int(entry.name))
    return found


@pytest.mark.slow
def test_a_run_killed_outright_leaves_no_process_behind(tmp_path):
    out = tmp_path / "run"
    process = _cosim_run(out, "--live", "--live-port", "0", "--live-rate", "1000")
    try:
        _wait_until_running(process, out / "bag")
        children = _children(process.pid)
        process.send_signal(signal.SIGKILL)
        process.communicate(timeout=60)
    finally:
        process.kill()
    assert process.returncode == -signal.SIGKILL
    time.sleep(0.2)
    assert [pid for pid in children if Path(f"/proc/{pid}").exists()] == []
    assert not any(
        str(out) in (p / "cmdline").read_text(errors="replace").replace("\0", " ")
        for p in Path("/proc").iterdir()
        if p.name.isdigit() and (p / "cmdline").exists()
    )


@pytest.mark.slow
def test_a_run_with_stand_ins_killed_outright_leaves_no_stand_in_behind(tmp_path):
    out = tmp_path / "run"
    process = subprocess.Popen(
        [sys.executable, "-m", "cosim", "run", "lab-mixed", "--standin", "--duration-s", "1000",
         "--out", str(out), "--quiet"],
        cwd=REPO, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
    )  # fmt: skip
    children: list[int] = []
    try:
        deadline = time.monotonic() + 60
        while not (children and (out / "bag" / "bag.mcap").exists()):
            assert process.poll() is None, process.communicate()
            assert time.monotonic() < deadline, "the run did not start in 60 s"
            children = _children(process.pid)
            time.sleep(0.1)
        process.send_signal(signal.SIGKILL)
        process.communicate(timeout=60)
        deadline = time.monotonic() + 5
        while any(Path(f"/proc/{pid}").exists() for pid in children):
            if time.monotonic() > deadline:
                break
            time.sleep(0.1)
        left = [pid for pid in children if Path(f"/proc/{pid}").exists()]
    finally:
        process.kill()
        for pid in children:  # the stand-ins this test started, whatever the outcome
            with contextlib.suppress(ProcessLookupError):
                os.kill(pid, signal.SIGKILL)
    assert left == []


numbers = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True).map(repr),
    st.integers(min_value=-(10**30), max_value=10**30).map(str),
    st.sampled_from(["", " 5\n", "-0", "1_000", "0x10", "1e309", "٣", "9" * 5000]),
    st.text(max_size=8),
)
flags = st.lists(
    st.one_of(
        st.tuples(st.just("--duration-s"), numbers),
        st.tuples(st.just("--seed"), numbers),
        st.tuples(st.just("--live-port"), numbers),
        st.tuples(st.just("--live-rate"), numbers),
        st.tuples(
            st.just("--live-host"),
            st.one_of(st.text(max_size=20), st.ip_addresses().map(str), st.just("999.1.1.1")),
        ),
        st.tuples(st.just("--out"), st.text(max_size=20)),
    ),
    max_size=4,
)


PARSER = build_parser()


@settings(max_examples=100, deadline=None)
@given(flags)
def test_any_run_flags_parse_or_exit_2_in_one_line(pairs):
    argv = ["run", "warehouse-random", *(item for pair in pairs for item in pair)]
    with contextlib.redirect_stderr(err := io.StringIO()):
        try:
            PARSER.parse_args(argv)
        except SystemExit as exit_:
            assert exit_.code == 2
            said = err.getvalue()
            assert said.count("\n") == 1 and said.startswith("cosim run: error: "), said


@settings(max_examples=40, deadline=None)
@given(flags)
def test_run_with_any_flags_reaches_the_runner_or_exits_2_in_one_line(pairs):
    argv = ["run", "warehouse-random", "--quiet", *(item for pair in pairs for item in pair)]
    with (
        tempfile.TemporaryDirectory() as folder,
        mock.patch("cosim.runner.execute.run") as run,
    ):
        done = cosim_main(*argv, cwd=Path(folder))
        assert done.returncode in (0, 2), done.stderr
        if done.returncode == 2:
            assert done.stderr.count("\n") == 1 and "Traceback" not in done.stderr, done.stderr
        else:
            assert run.call_count == 1 and done.stderr == ""

"""A failed run says whose fault it was, keeps what ran, and writes its traceback."""

import json
import operator
import sys
import traceback

import pytest

import cosim
from adapters.fleet.motion import FleetAdapter
from cosim.core.errors import BridgeError, ConfigError
from cosim.core.kernel import Stage
from cosim.core.plugins import PluginError, PluginInfo
from cosim.core.registry import registered
from cosim.runner.execute import execute
from cosim.runner.faults import FAILURE_FILE, Hung, InternalError, blame, fault_of
from cosim.scenario import parse_override

SMALL = {
    "world.size_m": [12.0, 12.0],
    "world.shelf_count": 4,
    "robots.count": 3,
    "lidar.beams": 90,
    "robots.driver": "waypoints",
    "scenario.duration_s": 5.0,
    "scenario.adapters": ["faulty"],
}


class DeviceError(Exception):
    """An exception whose constructor does not take its ``args`` back (SimPy cannot copy it)."""

    def __init__(self, code, text):
        super().__init__(f"device error {code}: {text}")


class Faulty:
    """An adapter that fails where the test tells it to."""

    name = "faulty"
    requires = ()
    where = ""

    def __init__(self, run):
        self.ticks = 0
        if self.where == "init":
            raise RuntimeError("cannot build")

    def start(self, run):
        if self.where == "start":
            _ = {}["missing"]
        run.kernel.every(100_000_000, self.tick, stage=Stage.CONTROL)
        if self.where.startswith("process"):
            run.kernel.process(self.poll(run.kernel))

    def poll(self, kernel):
        """A SimPy process: a generator the kernel resumes every 0.5 s."""
        while True:
            yield kernel.timeout(500_000_000)
            if kernel.now_ns < 1_500_000_000:
                continue
            if self.where == "process":
                raise KeyError("no such channel")
            if self.where == "process_odd":
                raise DeviceError(7, "unplugged")
            while self.where == "process_hang":
                pass

    def tick(self, now_ns):
        self.ticks += 1
        if self.where == "tick" and now_ns >= 2_000_000_000:
            raise ValueError(f"bad reading at {now_ns} ns")
        if self.where == "hang" and now_ns >= 1_000_000_000:
            while True:
                pass

    def finish(self, run):
        if self.where == "finish":
            raise ZeroDivisionError("division by zero")
        if self.where == "finish_list":
            return [1, 2]
        return {"faulty_ticks": self.ticks}


@pytest.fixture
def faulty(monkeypatch):
    """Registers :class:`Faulty`; the test sets where it fails."""

    def failing(where, **overrides):
        monkeypatch.setattr(Faulty, "where", where)
        return cosim.load_scenario("warehouse-random", {**SMALL, **overrides})

    with registered("cosim.adapters", "faulty", Faulty):
        yield failing


def _raised(scenario, **kwargs):
    with pytest.raises(PluginError) as caught:
        cosim.run(scenario, **kwargs)
    return caught.value


def test_a_plugin_raising_mid_run_is_named_with_its_code_and_the_simulated_time(faulty):
    error = _raised(faulty("tick"))
    assert error.plugin == PluginInfo("", "", "cosim.adapters", "faulty", f"{__name__}:Faulty")
    assert str(error).startswith(
        f"adapter 'faulty' ({__name__}:Faulty, given in code) raised ValueError: bad reading "
        "at 2000000000 ns in Faulty.tick (runner/test_faults.py:"
    )
    assert str(error).endswith("while running the simulation at t = 2 s simulated")
    # the exception the plugin raised, with its own frames, for a debugger or a notebook
    assert isinstance(error.__cause__, ValueError)
    assert traceback.extract_tb(error.__cause__.__traceback__)[-1].name == "tick"
    assert "ValueError: bad reading at 2000000000 ns" in error.details
    assert "Traceback" in error.details and "raise ValueError" in error.details


def test_what_ran_before_the_fault_is_kept_with_a_summary_marked_failed(faulty):
    kept = _raised(faulty("tick")).kept
    summary = kept.summary
    assert list(summary)[:3] == ["failed", "failure", "planned_duration_s"]
    assert summary["failure"]["kind"] == "plugin"
    assert summary["failure"]["plugin"]["name"] == "faulty"
    assert summary["sim_time_s"] == 2.0 and summary["planned_duration_s"] == 5.0
    assert summary["events"] > 0
    assert summary["faulty_ticks"] == 21  # its finish still sums up the 2 s it ran
    poses = kept.tables["poses"]
    assert 0 < poses["t_s"].max() <= 2.0


def test_the_run_folder_keeps_tables_bag_summary_and_the_traceback(faulty, tmp_path):
    out = tmp_path / "run"
    error = _raised(faulty("tick", **{"record.bag": "mcap"}), out=out)
    assert f"the traceback is in {out / FAILURE_FILE}" in str(error)
    assert f"the results of the 2 s simulated are in {out}/" in str(error)
    trace = (out / FAILURE_FILE).read_text()
    assert trace.startswith("adapter 'faulty'") and "Traceback (most recent call last)" in trace
    assert json.loads((out / "summary.json").read_text())["failure"]["kind"] == "plugin"
    assert (out / "tables" / "poses.parquet").is_file()
    assert (out / "bag" / "metadata.yaml").is_file()  # the bag is finished


@pytest.mark.parametrize(
    ("where", "doing", "said"),
    [
        ("start", "starting adapter 'faulty' at t = 0 s", "raised KeyError: 'missing'"),
        ("finish", "finishing adapter 'faulty' at t = 5 s", "raised ZeroDivisionError"),
        ("finish_list", "finishing adapter 'faulty'", "finish() returned list; expected a mapping"),
    ],
)
def test_a_fault_in_start_or_finish_says_which_and_keeps_the_run(faulty, where, doing, said):
    error = _raised(faulty(where))
    assert said in str(error) and doing in str(error)
    assert error.kept is not None and error.kept.summary["failure"]["kind"] == "plugin"


def test_a_plugin_that_cannot_be_built_is_named_before_anything_runs(faulty, tmp_path):
    error = _raised(faulty("init"), out=tmp_path / "run")
    assert "raised RuntimeError: cannot build in Faulty.__init__" in str(error)
    assert "while building the run" in str(error)
    assert error.kept is None and not (tmp_path / "run").exists()


def test_a_plugin_that_hangs_is_stopped_and_named_where_it_hangs(faulty):
    error = _raised(faulty("hang", **{"scenario.hang_timeout_s": 0.5}))
    assert "did not return within 0.5 s (scenario.hang_timeout_s) in Faulty.tick" in str(error)
    assert error.kept.summary["sim_time_s"] == 1.0


@pytest.mark.parametrize(
    ("where", "said"),
    [
        ("process", "raised KeyError: 'no such channel' in Faulty.poll"),
        ("process_odd", "raised DeviceError: device error 7: unplugged in Faulty.poll"),
    ],
)
def test_a_plugins_process_raising_is_named_with_its_own_frame(faulty, where, said):
    # SimPy raises a copy of a failed process's exception, built again from its args (or
    # failing to be); the run sees the one the plugin raised
    error = _raised(faulty(where))
    assert said in str(error), str(error)
    assert "at t = 1.5 s simulated" in str(error)
    assert error.kept.summary["sim_time_s"] == 1.5


def test_a_plugins_process_that_hangs_is_stopped_and_named(faulty):
    error = _raised(faulty("process_hang", **{"scenario.hang_timeout_s": 0.5}))
    assert "did not return within 0.5 s (scenario.hang_timeout_s) in Faulty.poll" in str(error)


def test_a_bug_of_cosim_mid_run_is_an_internal_error_keeping_what_ran(monkeypatch):
    # a C function raises where cosim calls it: no frame of any plugin is in the traceback
    monkeypatch.setattr(FleetAdapter, "_tick", operator.itemgetter(99))
    scenario = cosim.load_scenario("warehouse-random", {**SMALL, "scenario.adapters": []})
    with pytest.raises(InternalError) as caught:
        execute(scenario)
    error = caught.value
    assert str(error).startswith("cosim's own code raised TypeError")
    assert "while running the simulation at t = 0 s simulated" in str(error)
    assert error.kept.summary["failure"]["kind"] == "cosim"


def test_a_builtin_refused_at_the_boundary_is_cosims_bug_not_a_plugins():
    import adapters.navigation.contract  # noqa: F401 - declares the group's words

    builtin = PluginInfo("cosim", "0.1.0", "cosim.controllers", "dwa", "x:Dwa")
    refused = PluginError(builtin, "returned nan")
    fault = fault_of(refused, doing="computing commands", t_ns=3)
    assert isinstance(fault, InternalError)
    assert "(local controller 'dwa' (x:Dwa, cosim 0.1.0)) returned nan" in str(fault)


def test_an_input_error_met_mid_run_stays_one_keeping_its_traceback():
    # raised and caught in a module of cosim's (this test module holds plugins given in code)
    code = """
try:
    parse_override("no_equals_sign")
except ConfigError as raised:
    fault = fault_of(raised, doing="running the simulation", t_ns=0)
    error = raised
"""
    space = {"__name__": "cosim.runner.fake", "fault_of": fault_of, "ConfigError": ConfigError}
    space["parse_override"] = parse_override
    exec(compile(code, "fake.py", "exec"), space)
    assert space["fault"] is space["error"]
    assert "parse_override" in space["error"].details


def test_blame_finds_the_innermost_plugin_frame_inside_cosims_frames():
    def plugin_code():
        assert sys.modules[__name__]  # a frame of this module, a plugin given in code
        raise OSError("sensor gone")

    with registered("cosim.adapters", "faulty_blame", Faulty):
        try:
            operator.call(plugin_code)
        except OSError as error:
            info, where = blame(error.__traceback__)
    assert info is not None and info.package == "" and info.target.startswith(__name__)
    assert where.startswith("test_blame_finds_the_innermost_plugin_frame_inside_cosims_frames")
    assert "runner/test_faults.py:" in where


def test_errors_of_faults_cross_processes_whole():
    import pickle

    internal = InternalError("raised X", doing="running", t_ns=5, details="tb")
    assert str(pickle.loads(pickle.dumps(internal))) == str(internal)
    assert isinstance(Hung(2.0), BaseException) and not isinstance(Hung(2.0), Exception)
    assert issubclass(BridgeError, Exception)


def test_cosim_check_names_a_plugin_that_cannot_be_built(faulty, tmp_path):
    from tests.conftest import cosim_main

    faulty("init")
    done = cosim_main(
        "check", "warehouse-random", "--set", 'scenario.adapters=["faulty"]', cwd=tmp_path
    )
    assert done.returncode == 3
    assert done.stderr.startswith("cosim: plugin error: adapter 'faulty'")
    assert "raised RuntimeError: cannot build in Faulty.__init__" in done.stderr
    assert "Traceback (most recent call last)" in done.stderr  # no run folder to hold it

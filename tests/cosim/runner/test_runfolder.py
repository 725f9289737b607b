"""Run folders: their format, the mark that proves cosim wrote them, reading every format."""

import json
import shutil

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from cosim.core.errors import ExportError
from cosim.recording.bag import BAG_DIR
from cosim.runner.runfolder import (
    MARKER,
    RUN_FORMAT,
    bag_of,
    folder_format,
    is_cosim_folder,
    mark,
    read_run_scenario,
)
from tests.conftest import REPO

OLD_RUNS = REPO / "tests" / "oldruns"
"""Run folders written by older cosim (tests/oldruns/README.md says how)."""


def test_a_run_folder_of_99e8d54_is_read_as_it_was():
    folder = OLD_RUNS / "at-99e8d54"
    assert folder_format(folder) == 0
    scenario = read_run_scenario(folder)
    assert scenario.robots.count == 3 and scenario.world.size_m == (12.0, 12.0)
    assert scenario.notes == () and dict(scenario.carried) == {}


def test_a_run_folder_from_before_yield_s_was_renamed_is_read_with_one_note():
    folder = OLD_RUNS / "before-462a048"
    assert "yield_s = 10.0" in (folder / "scenario.toml").read_text()
    scenario = read_run_scenario(folder)
    assert scenario.humans.avoid_robots is True
    (note,) = scenario.notes
    assert note.startswith(f"note: {folder / 'scenario.toml'}: [humans] yield_s = 10.0 read as ")


def _with_summary(tmp_path, summary):
    folder = tmp_path / "run"
    shutil.copytree(OLD_RUNS / "at-99e8d54", folder)
    (folder / "summary.json").write_text(json.dumps(summary))
    return folder


def test_a_folder_without_a_format_is_of_format_0_and_one_of_today_of_format_1(tmp_path):
    assert folder_format(_with_summary(tmp_path, {"scenario": "x"})) == 0
    (tmp_path / "run" / "summary.json").write_text("garbled {")
    assert folder_format(tmp_path / "run") == 0  # the tables and scenario.toml are enough
    (tmp_path / "run" / "summary.json").write_text(json.dumps({"format": RUN_FORMAT}))
    assert folder_format(tmp_path / "run") == RUN_FORMAT


def test_a_folder_of_a_newer_format_is_refused_in_one_line(tmp_path):
    folder = _with_summary(tmp_path, {"format": RUN_FORMAT + 1})
    with pytest.raises(ExportError) as refused:
        read_run_scenario(folder)
    assert str(refused.value) == (
        f"{folder}: a run folder of format {RUN_FORMAT + 1}, written by a newer cosim; this one "
        f"reads formats 0 to {RUN_FORMAT} (upgrade cosim to read it)"
    )


@pytest.mark.parametrize("found", ["1", 1.5, -1, True, None, [1]])
def test_a_format_that_is_no_whole_number_is_named(tmp_path, found):
    folder = _with_summary(tmp_path, {"format": found})
    with pytest.raises(ExportError, match=r"summary\.json: format = .*: expected the format"):
        folder_format(folder)


def test_a_folder_without_scenario_toml_is_no_run_folder(tmp_path):
    with pytest.raises(ExportError, match=r"no scenario\.toml; expected a run folder"):
        read_run_scenario(tmp_path)


def test_only_a_marked_folder_or_a_run_of_format_0_is_cosims(tmp_path):
    assert is_cosim_folder(OLD_RUNS / "at-99e8d54")
    assert not is_cosim_folder(OLD_RUNS / "at-99e8d54", "map")
    mine = tmp_path / "mine"
    mine.mkdir()
    (mine / "summary.json").write_text(json.dumps({"scenario": "x"}))  # not a run's summary
    (mine / "scenario.toml").write_text("")
    assert not is_cosim_folder(mine)
    mark(mine)
    assert is_cosim_folder(mine) and not is_cosim_folder(mine, "map")
    assert (mine / MARKER).read_text().startswith(f"cosim run folder, format {RUN_FORMAT}\n")
    mark(mine, "map")
    assert is_cosim_folder(mine, "map") and not is_cosim_folder(mine)


def test_a_map_folder_of_format_0_is_known_by_its_summary(tmp_path):
    summary = {"scans": 30, "map_updates": 3, "recording_s": 2.9}
    (tmp_path / "summary.json").write_text(json.dumps(summary))
    assert is_cosim_folder(tmp_path, "map") and not is_cosim_folder(tmp_path)


def test_a_run_folder_names_its_bag_and_a_bag_names_itself(tmp_path):
    folder = tmp_path / "before-462a048"  # kept without its bag: a folder stands for it
    shutil.copytree(OLD_RUNS / "before-462a048", folder)
    (folder / BAG_DIR).mkdir()
    assert bag_of(folder) == folder / BAG_DIR
    assert bag_of(folder / BAG_DIR) == folder / BAG_DIR
    assert bag_of(OLD_RUNS / "at-99e8d54") == OLD_RUNS / "at-99e8d54"  # no bag: the bag reader says
    newer = tmp_path / "newer"
    shutil.copytree(folder, newer)
    (newer / "summary.json").write_text(json.dumps({"format": RUN_FORMAT + 1}))
    with pytest.raises(ExportError, match="written by a newer cosim"):
        bag_of(newer)


json_values = st.recursive(
    st.one_of(st.none(), st.booleans(), st.integers(), st.floats(), st.text(max_size=5)),
    lambda inner: st.one_of(
        st.lists(inner, max_size=3), st.dictionaries(st.text(max_size=5), inner, max_size=3)
    ),
    max_leaves=6,
)


@settings(
    max_examples=200, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(summary=st.one_of(json_values, st.dictionaries(st.just("format"), json_values)))
def test_any_summary_gives_a_format_or_one_line_naming_the_file(summary, tmp_path):
    (tmp_path / "summary.json").write_text(json.dumps(summary))
    try:
        found = folder_format(tmp_path)
    except ExportError as error:
        assert "\n" not in str(error) and str(error).startswith(str(tmp_path))
    else:
        assert 0 <= found <= RUN_FORMAT
    assert isinstance(is_cosim_folder(tmp_path), bool)

"""Fuzzing --resume (cosim.studies.folder.inspect) over damaged study folders."""

import shutil
from pathlib import Path
from tempfile import TemporaryDirectory

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cosim.core.errors import ConfigError, ExportError
from cosim.studies import load_study, run_study
from cosim.studies.folder import FolderState, inspect
from cosim.studies.spec import StudySpec
from tests.cosim.studies.small import ok_row, scenario_file, small_study

RUNS = ["0000_s1", "0000_s2", "0000_s3"]
JUNK = [b"", b"junk", b"\xff\xfe", b"[" * 50_000, b"[]", b"{}", b'{"runs": 5}', b'{"runs": []}']
JUNK += [b'{"run_id": "0000_s2", "status": "ok"}', b'{"runs": [1, {"run_id": 2}]}', b"null"]


@pytest.fixture(scope="module")
def finished_study(tmp_path_factory: pytest.TempPathFactory) -> tuple[StudySpec, Path]:
    """A study of three tiny runs, finished once for the module: its spec and folder."""
    folder = tmp_path_factory.mktemp("finished")
    scenario_file(folder)
    spec = load_study(small_study(folder, scenario="scenario.toml"))
    run_study(spec, folder / "out", workers=1)
    return spec, folder / "out"


def _remove(path: Path) -> None:
    if not path.parent.is_dir():
        return
    if path.is_dir() and not path.is_symlink():
        shutil.rmtree(path)
    else:
        path.unlink(missing_ok=True)


def _put(path: Path, data: bytes | None) -> None:
    """Replace whatever is at ``path`` by a file of ``data`` (None: a folder), if its folder is."""
    if not path.parent.is_dir():
        return
    _remove(path)
    if data is None:
        path.mkdir()
    else:
        path.write_bytes(data)


def _damage(out: Path, how: str, run: str, junk: bytes) -> None:
    runs, row = out / "runs", out / "runs" / run / "row.json"
    if how == "delete plan":
        _remove(out / "plan.json")
    elif how == "garble plan":
        _put(out / "plan.json", junk)
    elif how == "plan is a folder":
        _put(out / "plan.json", None)
    elif how == "garble row":
        _put(row, junk)
    elif how == "cut row" and row.is_file():
        text = row.read_bytes()
        row.write_bytes(text[: len(junk) % max(len(text), 1)])
    elif how == "delete row":
        _remove(row)
    elif how == "row is a folder":
        _put(row, None)
    elif how == "delete scenario":
        _remove(runs / run / "scenario.toml")
    elif how == "garble scenario":
        _put(runs / run / "scenario.toml", junk)
    elif how == "delete run":
        _remove(runs / run)
    elif how == "partial run":  # as cosim wrote a run on its way before run folders had formats
        _put(runs / f"{run}.partial", None)
        _put(runs / f"{run}.partial" / "row.json", junk)
    elif how == "staged run":  # a run on its way, cut short
        _put(runs / ".cosim-partial-a1b2c3d4", None)
        _put(runs / ".cosim-partial-a1b2c3d4" / "row.json", junk)
    elif how == "stray files":
        _put(out / "notes.txt", junk)
        _put(runs / "README", junk)
        _put(runs / "stray", None)
    elif how == "runs is a file":
        _put(runs, junk)


DAMAGES = ["delete plan", "garble plan", "plan is a folder", "garble row", "cut row"]
DAMAGES += ["delete row", "row is a folder", "delete scenario", "garble scenario"]
DAMAGES += ["delete run", "partial run", "staged run", "stray files", "runs is a file"]
damages = st.lists(
    st.tuples(
        st.sampled_from(DAMAGES),
        st.sampled_from(RUNS),
        st.one_of(st.sampled_from(JUNK), st.binary(max_size=40)),
    ),
    max_size=4,
)


@pytest.mark.slow
@settings(max_examples=40, deadline=None)
@given(damage=damages)
def test_resume_over_any_damage_decides_or_refuses_and_trusts_only_readable_ok_rows(
    finished_study, damage
):
    spec, source = finished_study
    with TemporaryDirectory() as scratch:
        out = Path(scratch) / "out"
        shutil.copytree(source, out)
        for how, run, junk in damage:
            _damage(out, how, run, junk)
        try:
            state = inspect(spec, out, resume=True)
        except (ConfigError, ExportError) as error:
            assert "\n" not in str(error) and str(out) in str(error)
            return
        assert isinstance(state, FolderState)
        assert state.done <= set(RUNS)
        for run in state.done:
            assert ok_row(out / "runs" / run / "row.json"), (run, damage)
        if not damage:
            assert state.done == set(RUNS) and not state.notes
        for note in state.notes:
            assert "\n" not in note

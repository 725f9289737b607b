"""Renamed keys: the declared table matches the code and git, and old files read today."""

import copy
import re
import subprocess

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import cosim.scenario.migrations as migrations
from cosim.core.errors import ConfigError
from cosim.scenario.fields import field_names
from cosim.scenario.migrations import (
    RENAMES,
    Rename,
    leftover,
    migrate,
    migrate_dotted,
    renamed_hint,
)
from cosim.scenario.model import section_classes
from tests.conftest import REPO

RAYS = Rename(
    old="lidar.rays",
    new="lidar.beams",
    commit="0000000",
    convert=int,
    same_meaning=True,
    change="the same count",
)
"""A rename of the same meaning (none in the history yet), to test what such a rename does."""


@pytest.mark.parametrize("rename", RENAMES, ids=lambda r: r.old)
def test_every_rename_leads_from_a_key_no_section_has_to_one_a_section_has(rename):
    classes = section_classes()
    old_section, new_section = rename.sections
    assert rename.old.partition(".")[2] not in field_names(classes[old_section])
    assert rename.new.partition(".")[2] in field_names(classes[new_section])


def _git(*args):
    return subprocess.run(["git", *args], cwd=REPO, capture_output=True, text=True)


@pytest.mark.parametrize("rename", RENAMES, ids=lambda r: r.old)
def test_every_rename_names_the_commit_that_took_the_old_key_away(rename):
    if _git("cat-file", "-e", f"{rename.commit}^{{commit}}").returncode:
        pytest.skip(f"commit {rename.commit} is not in this clone (shallow, or an archive)")
    diff = _git("show", "--format=", rename.commit, "--", "*.py").stdout
    old, new = rename.old.partition(".")[2], rename.new.partition(".")[2]
    assert f"\n-    {old}: " in diff and f"\n+    {new}: " in diff


KEY_LINE = re.compile(r"([-+])    (\w+): [^=\n]+= param\(")
"""A section's key declared (``+``) or taken away (``-``) in a diff."""


def test_the_history_has_no_other_key_taken_away_from_a_section():
    """Every key a commit took from the sections and did not declare again is in RENAMES."""
    if _git("cat-file", "-e", "462a048^{commit}").returncode:
        pytest.skip("the history is not in this clone (shallow, or an archive)")
    log = _git(
        "log", "-p", "--no-renames", "--format=COMMIT %H", "--",
        "cosim/scenario", "cosim/scenario.py", "adapters/*/settings.py",
    )  # fmt: skip
    taken: dict[str, set[str]] = {}
    for commit in log.stdout.split("COMMIT ")[1:]:
        name = commit.split("\n", 1)[0]
        lines = KEY_LINE.findall(commit)
        gone = {key for sign, key in lines if sign == "-"} - {k for s, k in lines if s == "+"}
        if gone:
            taken[name] = gone
    found = sorted((key, c) for c, keys in taken.items() for key in keys)
    declared = sorted((r.old.partition(".")[2], r.commit) for r in RENAMES)
    assert len(found) == len(declared)
    for (key, commit), (old, short) in zip(found, declared, strict=True):
        assert commit.startswith(short) and key == old


def test_yield_s_is_read_as_avoid_robots_with_a_note_naming_the_commit():
    raw = {"humans": {"workers": 3, "yield_s": 10.0}}
    migrated = migrate(raw, "old/scenario.toml")
    assert migrated.tables == {"humans": {"workers": 3, "avoid_robots": True}}
    assert migrated.notes == (
        "note: old/scenario.toml: [humans] yield_s = 10.0 read as humans.avoid_robots = true "
        "(renamed in 462a048: people keep clear of robots through a speed model instead of "
        "stopping for one at most yield_s s; yield_s = 0 (never stopping) is avoid_robots = "
        "false)",
    )
    assert migrated.applied == RENAMES
    assert raw == {"humans": {"workers": 3, "yield_s": 10.0}}  # the file's tables untouched


def test_yield_s_of_zero_is_no_avoiding():
    assert migrate({"humans": {"yield_s": 0}}, "f").tables == {"humans": {"avoid_robots": False}}


def test_a_file_with_both_names_keeps_the_new_and_says_the_old_is_ignored():
    migrated = migrate({"humans": {"yield_s": 5.0, "avoid_robots": False}}, "f.toml")
    assert migrated.tables == {"humans": {"avoid_robots": False}}
    assert migrated.notes == (
        "note: f.toml: [humans] yield_s = 5.0 ignored (renamed humans.avoid_robots in "
        "462a048, set too)",
    )
    assert migrated.applied == ()


@pytest.mark.parametrize("value", ["ten", True, [1.0], {"s": 1}])
def test_an_old_value_the_key_never_took_is_one_line_naming_it(value):
    with pytest.raises(ConfigError) as refused:
        migrate({"humans": {"yield_s": value}}, "f.toml")
    assert str(refused.value).startswith("f.toml: [humans] yield_s = ")
    assert str(refused.value).endswith(
        ": expected a number of seconds (the key was renamed humans.avoid_robots in 462a048)"
    )


def test_a_rename_whose_model_changed_is_left_in_place_where_a_scenario_runs():
    raw = {"humans": {"yield_s": 10.0}}
    migrated = migrate(raw, "f", meaning_changes=False)
    assert migrated.tables == raw and migrated.notes == ()
    assert leftover(migrated.tables) is RENAMES[0]
    assert renamed_hint(RENAMES[0]) == (
        ": renamed humans.avoid_robots in 462a048 (people keep clear of robots through a speed "
        "model instead of stopping for one at most yield_s s; yield_s = 0 (never stopping) is "
        "avoid_robots = false); set humans.avoid_robots instead"
    )


def test_a_rename_of_the_same_meaning_migrates_where_a_scenario_runs_too():
    migrated = migrate({"lidar": {"rays": 90}}, "f", meaning_changes=False, renames=(RAYS,))
    assert migrated.tables == {"lidar": {"beams": 90}} and migrated.applied == (RAYS,)
    assert leftover(migrated.tables, renames=(RAYS,)) is None


def test_dotted_keys_migrate_only_for_renames_of_the_same_meaning(monkeypatch):
    monkeypatch.setattr(migrations, "RENAMES", (*RENAMES, RAYS))
    values = {"lidar.rays": 90, "humans.yield_s": 10.0, "robots.count": 3}
    assert migrate_dotted(values) == {"lidar.beams": 90, "humans.yield_s": 10.0, "robots.count": 3}
    both = {"lidar.rays": 90, "lidar.beams": 180}
    assert migrate_dotted(both) == both


tables = st.dictionaries(
    st.sampled_from(["humans", "lidar", "world", "x"]),
    st.one_of(
        st.dictionaries(
            st.sampled_from(["yield_s", "avoid_robots", "workers", "rays"]),
            st.one_of(st.floats(), st.integers(), st.booleans(), st.text(max_size=3)),
            max_size=3,
        ),
        st.integers(),
        st.text(max_size=3),
    ),
    max_size=4,
)


@settings(max_examples=200, deadline=None)
@given(tables)
def test_any_tables_migrate_or_are_refused_in_one_line_and_are_never_changed(raw):
    before = copy.deepcopy(raw)
    try:
        migrated = migrate(raw, "f.toml")
    except ConfigError as error:
        assert "\n" not in str(error) and str(error).startswith("f.toml: [humans] yield_s = ")
    else:
        assert leftover(migrated.tables) is None or not isinstance(
            migrated.tables.get("humans"), dict
        )
        assert all("\n" not in note for note in migrated.notes)
    assert raw == before

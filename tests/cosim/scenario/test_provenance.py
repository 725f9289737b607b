"""``[provenance]``: read back and ignored by the run, refused when malformed, noted when stale."""

from __future__ import annotations

from importlib.metadata import version
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import cosim
from cosim.core.errors import ConfigError
from cosim.scenario import dump_scenario, scenario_from_text
from cosim.scenario.provenance import provenance_note, split_provenance

COSIM_VERSION = version("cosim")


def _write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "s.toml"
    path.write_text(text)
    return path


def test_a_provenance_table_is_read_back_and_changes_nothing_of_the_run(tmp_path):
    text = '[provenance]\ncosim = "0.1.0"\n"zope.interface" = "6.0"\n\n[robots]\ncount = 3\n'
    scenario = cosim.load_scenario(_write(tmp_path, text))
    assert dict(scenario.resolved_with) == {"cosim": "0.1.0", "zope.interface": "6.0"}
    assert scenario == cosim.load_scenario(_write(tmp_path, "[robots]\ncount = 3\n"))
    assert "provenance" not in scenario.sections


def test_a_dumped_provenance_loads_back_as_written(small_scenario):
    used = {"cosim": COSIM_VERSION, "lab.kit": '1.0+"odd"'}
    text = dump_scenario(small_scenario, provenance=used)
    assert text.splitlines()[3:6] == [
        "[provenance]",
        f'cosim = "{COSIM_VERSION}"',
        '"lab.kit" = "1.0+\\"odd\\""',
    ]
    back = scenario_from_text(text, "run/scenario.toml")
    assert back == small_scenario and dict(back.resolved_with) == used
    assert "[provenance]" not in dump_scenario(back)  # what a run used is the run's to say


def test_the_resolved_with_survives_a_changed_seed_and_a_trip_to_another_process(small_scenario):
    import pickle

    scenario = scenario_from_text(dump_scenario(small_scenario, provenance={"a": "1"}), "x")
    assert dict(scenario.with_seed(7).resolved_with) == {"a": "1"}
    assert dict(pickle.loads(pickle.dumps(scenario)).resolved_with) == {"a": "1"}


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ('provenance = "cosim 0.1.0"\n', "provenance = 'cosim 0.1.0': expected a [provenance]"),
        ("[provenance]\ncosim = 3\n", '[provenance] cosim = 3: expected its version as a string'),
        ('[provenance]\ncosim = ""\n', "[provenance] cosim = '': expected its version"),
        ('[provenance]\n"no such" = "1"\n', "[provenance] no such: expected a package name"),
        ("[provenance.cosim]\nv = 1\n", "[provenance] cosim = {v = 1}: expected its version"),
    ],
)  # fmt: skip
def test_a_malformed_provenance_is_refused_in_one_line_naming_file_and_key(
    tmp_path, text, expected
):
    path = _write(tmp_path, text)
    with pytest.raises(ConfigError) as refused:
        cosim.load_scenario(path)
    assert str(refused.value).startswith(f"{path}: {expected}")
    assert "\n" not in str(refused.value)


def test_an_override_of_provenance_is_refused_as_no_setting():
    with pytest.raises(ConfigError, match=r"^--set provenance\.cosim: \[provenance\] says which"):
        cosim.load_scenario("warehouse-random", {"provenance.cosim": "1"})


@settings(max_examples=200, deadline=None)
@given(
    st.one_of(
        st.dictionaries(st.text(max_size=12), st.one_of(st.text(max_size=12), st.integers())),
        st.text(max_size=12),
        st.integers(),
        st.lists(st.text(max_size=4), max_size=3),
    )
)
def test_any_provenance_is_taken_as_package_versions_or_refused_in_one_line(table):
    try:
        sections, resolved = split_provenance({"provenance": table, "robots": {}}, "s.toml", {})
    except ConfigError as refused:
        assert str(refused).startswith("s.toml: ") and "provenance" in str(refused)
        assert "\n" not in str(refused)
        return
    assert sections == {"robots": {}}
    assert resolved == table
    assert all(isinstance(v, str) and v for v in resolved.values())


def test_versions_that_match_what_is_installed_are_not_noted():
    assert provenance_note("runs/a/scenario.toml", {"cosim": COSIM_VERSION}) is None
    assert provenance_note("runs/a/scenario.toml", {}) is None


def test_a_version_installed_otherwise_or_a_package_gone_is_one_note():
    note = provenance_note(
        "runs/a/scenario.toml",
        {"cosim": "0.0.1", "hypothesis": version("hypothesis"), "nosuchkit": "0.1.0"},
    )
    assert note == (
        "note: runs/a/scenario.toml was resolved with cosim 0.0.1, nosuchkit 0.1.0; installed: "
        f"cosim {COSIM_VERSION}, no nosuchkit (results may differ from that run's)"
    )


def test_a_provenance_key_a_file_set_is_no_override():
    origins = {("provenance", "cosim"): "base.toml", ("robots", "count"): "--set robots.count"}
    _, resolved = split_provenance({"provenance": {"cosim": "0.1.0"}}, "s.toml", origins)
    assert resolved == {"cosim": "0.1.0"}
    origins[("provenance", "cosim")] = "study provenance.cosim"
    with pytest.raises(ConfigError, match=r"^study provenance\.cosim: \[provenance\] says"):
        split_provenance({"provenance": {"cosim": "0.1.0"}}, "s.toml", origins)


def test_a_section_registered_as_provenance_is_refused_and_the_table_still_reads(tmp_path):
    from dataclasses import dataclass

    from cosim.core.errors import RegistryError
    from cosim.core.registry import registered
    from cosim.scenario.model import section_registry

    @dataclass(frozen=True)
    class Mine:
        level: int = 1

    with registered("cosim.sections", "provenance", Mine):
        with pytest.raises(RegistryError, match=r"takes the name \[provenance\], which a run"):
            section_registry().get("provenance")
        path = _write(tmp_path, '[provenance]\ncosim = "0.1.0"\n')
        assert dict(cosim.load_scenario(path).resolved_with) == {"cosim": "0.1.0"}

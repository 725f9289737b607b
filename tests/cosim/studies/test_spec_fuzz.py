"""Fuzzing study files (cosim.studies.spec.read_study): a spec, or one line naming the file."""

import json
import math
from pathlib import Path
from tempfile import TemporaryDirectory

from hypothesis import given, settings
from hypothesis import strategies as st

from cosim.core.errors import ConfigError
from cosim.studies.spec import SEED_MAX, StudySpec, read_study

KEYS = ["network.latency_ms", "robots.count", "assignment.protocol", "scenario.seed"]
KEYS += ["scenario.duration_s", "record.bag", "record.tables", "world.size_m", "nodot"]
KEYS += ["a.b.c", "", " ", "network.", ".x", "x\ny"]

scalars = st.one_of(
    st.booleans(),
    st.integers(min_value=-(2**70), max_value=2**70),
    st.sampled_from([0, 1, -1, SEED_MAX, SEED_MAX + 1, 10**30, 2**64]),
    st.floats(allow_nan=True, allow_infinity=True),
    st.text(max_size=8),
    st.sampled_from(["..", "../escape", "a/b", "warehouse-random", "fleet50", "\x00", "é" * 40]),
)
values = st.recursive(
    scalars,
    lambda inner: st.one_of(
        st.lists(inner, max_size=4), st.dictionaries(st.text(max_size=5), inner, max_size=3)
    ),
    max_leaves=6,
)
study_values = {  # key: (values it accepts, values it refuses)
    "name": (
        st.sampled_from(["s", "comm_sweep", "v1.2+rc", "x" * 100]),
        st.sampled_from(["..", "a/b", "", ".", "x" * 101, "../escape", "a b"]),
    ),
    "scenario": (
        st.sampled_from(["warehouse-random", "fleet50"]),
        st.sampled_from(["nowhere.toml", "", ".", "/", "study.toml/x"]),
    ),
    "seeds": (
        st.one_of(st.integers(1, 3), st.lists(st.integers(0, SEED_MAX), min_size=1, max_size=3)),
        st.one_of(st.integers(-2, 0), st.lists(st.integers(-(2**65), 2**65), max_size=3)),
    ),
    "duration_s": (
        st.floats(min_value=0.1, max_value=10),
        st.one_of(st.floats(max_value=0), st.sampled_from([math.nan, math.inf])),
    ),
    "tables": (
        st.one_of(st.booleans(), st.lists(st.sampled_from(["poses", "tasks"]), max_size=2)),
        st.lists(st.integers(), min_size=1, max_size=2),
    ),
    "description": (st.text(max_size=5), st.integers()),
}
report_values = {
    "x": st.sampled_from(["robots.count", "network.latency_ms", "tasks_per_min", "", "a.b"]),
    "hue": st.sampled_from(["assignment.protocol", "seed", "nope.nope"]),
    "facet": st.sampled_from(["robots.count", "x"]),
    "metrics": st.lists(st.sampled_from(["tasks_per_min", "", "no_such_metric"]), max_size=2),
    "heatmaps": st.lists(st.sampled_from(["tasks_per_min", "conflicts"]), max_size=2),
    "loglog": st.lists(st.sampled_from(["wall_time_s", "tasks_per_min"]), max_size=2),
    "timeseries": st.lists(
        st.dictionaries(st.sampled_from(["table", "y", "where", "whre"]), values, max_size=3),
        max_size=2,
    ),
}


@st.composite
def study_documents(draw):
    """A study file as a dict: mostly the right shape, with wrong values and keys mixed in."""
    study = {}
    spoiled = draw(st.sampled_from([None] * 6 + [*study_values]))  # one key at most is wrong
    for key, (accepted, refused) in study_values.items():
        if key != spoiled:
            if key in ("name", "scenario") or draw(st.booleans()):
                study[key] = draw(accepted)
        elif draw(st.integers(0, 3)):  # else left out
            study[key] = draw(st.one_of(refused, values))
    if draw(st.integers(0, 9)) == 9:
        study[draw(st.sampled_from(["seed", "nmae", "x"]))] = draw(values)
    doc = {"study": study}
    for section in ("grid", "overrides"):
        if draw(st.booleans()):
            table = st.dictionaries(st.sampled_from(KEYS), values, max_size=3)
            doc[section] = draw(values if draw(st.integers(0, 6)) == 6 else table)
    if draw(st.booleans()):
        case = st.dictionaries(st.sampled_from(KEYS), values, max_size=2)
        doc["cases"] = draw(values if draw(st.integers(0, 6)) == 6 else st.lists(case, max_size=3))
    if draw(st.booleans()):
        report = draw(
            st.dictionaries(st.sampled_from([*report_values, "mtrics"]), values, max_size=1)
        )
        for key, strategy in report_values.items():
            if draw(st.integers(0, 2)) == 2:
                report[key] = draw(strategy)
        doc["report"] = report
    if draw(st.integers(0, 15)) == 15:
        doc[draw(st.sampled_from(["plots", "Study", "grids"]))] = {"a": 1}
    return doc


def quoted(text):
    """A TOML basic string (control characters escaped, the rest as is)."""
    return json.dumps(text, ensure_ascii=False).replace("\x7f", "\\u007f")


def toml_value(value):
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if math.isnan(value):
            return "nan"
        if math.isinf(value):
            return "inf" if value > 0 else "-inf"
        return repr(value)
    if isinstance(value, str):
        return quoted(value)
    if isinstance(value, list):
        return "[" + ", ".join(toml_value(v) for v in value) + "]"
    return "{" + ", ".join(f"{quoted(k)} = {toml_value(v)}" for k, v in value.items()) + "}"


def toml_document(doc):
    lines = []
    for section, table in doc.items():
        if (
            section == "cases"
            and isinstance(table, list)
            and all(isinstance(c, dict) for c in table)
        ):
            for case in table:
                lines.append("[[cases]]")
                lines += [f"{quoted(k)} = {toml_value(v)}" for k, v in case.items()]
        elif isinstance(table, dict):
            lines.append(f"[{quoted(section)}]")
            lines += [f"{quoted(k)} = {toml_value(v)}" for k, v in table.items()]
        else:  # a section given as a plain value
            lines.insert(0, f"{quoted(section)} = {toml_value(table)}")
    return "\n".join(lines) + "\n"


@settings(max_examples=50, deadline=None)
@given(doc=study_documents())
def test_any_study_file_is_read_or_refused_in_one_line_naming_the_file(doc):
    with TemporaryDirectory() as folder:
        path = Path(folder) / "study.toml"
        path.write_text(toml_document(doc), encoding="utf-8", errors="surrogatepass")
        try:
            spec = read_study(path)
        except ConfigError as error:
            message = str(error)
            assert str(path) in message and "\n" not in message, message
            return
    assert isinstance(spec, StudySpec)
    assert all(0 <= seed <= SEED_MAX for seed in spec.seeds)
    assert "/" not in spec.name and spec.name.strip(".")
    assert len({r.run_id for r in spec.runs()}) == len(spec.runs())
    for run in spec.runs():
        assert "scenario.seed" not in run.overrides

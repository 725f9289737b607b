"""Study figures drop no run that leaves a grouping key unset (cosim.studies.unset)."""

import json
from pathlib import Path

import pandas as pd
import pytest

from cosim.studies import load_study, run_study
from cosim.studies.reporting import report_study
from cosim.studies.unset import fill_unset
from tests.cosim.studies.small import scenario_file, small_study

CASES = """
[[cases]]
"lidar.beams" = 45

[[cases]]
"robots.count" = 1

[[cases]]
"robots.count" = 3
"lidar.beams" = 90

[[cases]]
"world.size_m" = [14.0, 14.0]

[report]
x = "robots.count"
facet = "lidar.beams"
hue = "world.size_m"
metrics = ["collisions"]
"""
"""Four cases; all but one leave some grouping key to the scenario file (2 robots, a 12 m hall)
or to the defaults (360 beams)."""
X, FACET, HUE = "robots.count", "lidar.beams", "world.size_m"
FIGURE_CSV = "figures/collisions_vs_robots.count.csv"


def _study(folder: Path, seeds: str) -> Path:
    folder.mkdir(exist_ok=True)
    scenario_file(folder)
    return small_study(folder, scenario="scenario.toml", seeds=seeds, extra=CASES)


@pytest.fixture(scope="module")
def study(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, list[str]]:
    """A real study of the cases above over two seeds, reported; its folder, what it told."""
    folder = tmp_path_factory.mktemp("unset")
    told: list[str] = []
    run_study(load_study(_study(folder, "[1, 2]")), folder / "out", workers=1, notify=told.append)
    return folder / "out", told


def test_every_run_appears_in_the_figure_csv_under_the_value_its_scenario_used(study):
    out, told = study
    drawn = pd.read_csv(out / FIGURE_CSV)
    assert drawn["n"].sum() == 8  # every run of the 4 cases x 2 seeds
    groups = {
        (int(row[FACET]), row[HUE], int(row[X])): row["n"] for row in drawn.to_dict("records")
    }
    hall, other = "[12.0, 12.0]", "[14.0, 14.0]"  # the scenario file's hall, the case's
    assert groups == {
        (45, hall, 2): 2,  # robots from the scenario file
        (360, hall, 1): 2,  # the lidar's default beams
        (90, hall, 3): 2,
        (360, other, 2): 2,
    }
    assert told == []


def test_the_results_hold_the_value_each_run_used_and_the_report_no_nan(study):
    out, _ = study
    results = pd.read_parquet(out / "results.parquet")
    assert results[[X, FACET, HUE]].notna().all().all()
    for row in results.to_dict("records"):
        resolved = (out / "runs" / row["run_id"] / "scenario.toml").read_text()
        assert f"count = {int(row[X])}\n" in resolved
        assert f"beams = {int(row[FACET])}\n" in resolved
        assert f"size_m = {row[HUE]}\n" in resolved
    report = (out / "report.md").read_text()
    assert "nan" not in report and "left out" not in report


def test_a_run_whose_scenario_is_lost_is_left_out_and_named_in_the_report_and_on_stderr(
    tmp_path, capsys
):
    spec = load_study(_study(tmp_path / "study", "[1]"))
    out = tmp_path / "out"
    run_study(spec, out, workers=1, report=False)
    (out / "runs" / "0001_s1" / "scenario.toml").unlink()  # robots.count set, the rest not
    report_study(spec, out)
    lines = [
        f"study: 1 ok run left out of the figures grouped by `{key}` (neither its row nor its "
        "scenario.toml has a value of it; the tables show them under nan): `0001_s1`."
        for key in (HUE, FACET)  # the order of x, hue, facet
    ]
    assert capsys.readouterr().err == "\n".join(lines) + "\n"
    report = (out / "report.md").read_text()
    assert all(line.removeprefix("study: ") in report for line in lines)
    drawn = pd.read_csv(out / FIGURE_CSV)
    assert drawn["n"].sum() == 3  # the other three runs


def _folder(tmp_path: Path, rows: list[dict]) -> Path:
    pd.DataFrame(rows).to_parquet(tmp_path / "results.parquet", index=False)
    return tmp_path


def _row(run_id: str, **cells: object) -> dict:
    return {"run_id": run_id, "seed": 1, "status": "ok", "error": "", **cells}


def _scenario(tmp_path: Path, run_id: str, text: str) -> None:
    folder = tmp_path / "runs" / run_id
    folder.mkdir(parents=True)
    (folder / "scenario.toml").write_text(text)


def test_a_list_value_is_filled_as_the_json_text_a_row_holds(tmp_path):
    folder = _folder(tmp_path, [_row("a", **{HUE: "[9.0, 9.0]"}), _row("b", **{HUE: None})])
    _scenario(tmp_path, "b", "[world]\nsize_m = [12.0, 12.0]\n")
    assert fill_unset(folder, [None, HUE, None]) == []
    assert list(pd.read_parquet(folder / "results.parquet")[HUE]) == [
        "[9.0, 9.0]",
        json.dumps([12.0, 12.0]),
    ]


def test_a_metric_some_runs_do_not_report_names_them_without_touching_the_results(tmp_path):
    rows = [_row(f"r{i}", tasks_per_min=None if i % 2 else 1.0) for i in range(24)]
    folder = _folder(tmp_path, rows)
    before = (folder / "results.parquet").read_bytes()
    (note,) = fill_unset(folder, ["tasks_per_min"])
    assert note.startswith(
        "12 ok runs left out of the figures grouped by `tasks_per_min` (it reports no value "
        "of it; the tables show them under nan): `r1`, `r3`,"
    )
    assert note.endswith("`r19` and 2 more.")
    assert (folder / "results.parquet").read_bytes() == before


def test_failed_runs_are_not_filled_nor_named(tmp_path):
    rows = [_row("a", **{X: 2}), {**_row("b", **{X: None}), "status": "error"}]
    folder = _folder(tmp_path, rows)
    assert fill_unset(folder, [X]) == []
    assert pd.read_parquet(folder / "results.parquet")[X].isna().tolist() == [False, True]


def test_a_run_of_before_a_rename_is_grouped_under_the_new_keys_value(tmp_path):
    (tmp_path / "runs" / "0000_s1").mkdir(parents=True)
    (tmp_path / "runs" / "0000_s1" / "scenario.toml").write_text("[humans]\nyield_s = 0.0\n")
    results = pd.DataFrame(
        {"run_id": ["0000_s1"], "seed": [1], "status": ["ok"], "humans.avoid_robots": [None]}
    )
    results.to_parquet(tmp_path / "results.parquet")
    assert fill_unset(tmp_path, ["humans.avoid_robots"]) == []
    filled = pd.read_parquet(tmp_path / "results.parquet")
    assert filled["humans.avoid_robots"].tolist() == [False]

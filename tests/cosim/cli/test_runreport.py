"""What ``cosim run`` prints when a run is done."""

from pathlib import Path

import cosim
from cosim.cli.runreport import print_run
from tests.conftest import SMALL


def test_a_run_is_reported_with_its_speed_highlights_results_and_bag(tmp_path, capsys):
    out = tmp_path / "run"
    scenario = cosim.load_scenario("warehouse-random", {**SMALL, "robots.driver": "tasks"})
    result = cosim.run(scenario, duration_s=20.0, out=out)
    print_run(result, out, [])
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].startswith("warehouse-random seed 1: ")
    assert f"{result.summary['robots']} robots" in lines[0]
    done = result.summary["tasks_completed"]
    assert lines[1].startswith(f"  {done:,} task")  # with tasks, the tasks lead
    assert "goals reached" not in lines[1]
    assert lines[2].startswith(f"results: {out}/  (summary.json, scenario.toml, tables/: ")
    assert lines[3].startswith(f"bag: {out / 'bag'}/  (")


def test_one_of_a_kind_is_said_in_the_singular_and_old_figures_are_named_as_old(tmp_path, capsys):
    out = tmp_path / "run"
    result = cosim.run(cosim.load_scenario("warehouse-random", SMALL), duration_s=2.0, out=out)
    result.summary["collisions"] = 1
    (out / "figures").mkdir()
    (out / "figures" / "old.png").write_bytes(b"")
    print_run(result, Path(out), [])
    printed = capsys.readouterr().out
    assert "1 collision" in printed and "1 collisions" not in printed
    assert "figures/: kept from before, not of this run" in printed

"""``cosim world``: the same world as a run, the files asked for, one-line refusals."""

import xml.etree.ElementTree as ET

import numpy as np
import pytest

import cosim
from adapters.world.files import read_map
from adapters.world.warehouse import scenario_warehouse
from cosim.cli.world import world_command
from cosim.core.errors import ConfigError, ScenarioError
from cosim.runner.assembly import assemble
from models.world.warehouse import Warehouse, ground_truth_grid

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


def test_world_command_builds_the_same_world_as_a_run_with_that_seed(small_scenario):
    scenario = small_scenario.with_seed(11)
    run_world = assemble(scenario).run.service(Warehouse)
    world = scenario_warehouse(scenario)
    np.testing.assert_array_equal(world.shelves, run_world.shelves)
    np.testing.assert_array_equal(world.walls, run_world.walls)
    np.testing.assert_array_equal(world.starts, run_world.starts)
    other = scenario_warehouse(scenario.with_seed(12))
    assert not np.array_equal(other.shelves, world.shelves)


def test_world_command_writes_the_requested_files_and_returns_them(tmp_path, small_scenario):
    written = world_command(
        small_scenario,
        png=tmp_path / "w.png",
        map_yaml=tmp_path / "map.yaml",
        sdf=tmp_path / "w.sdf",
        resolution_m=0.1,
    )
    assert written == [tmp_path / n for n in ("w.png", "map.yaml", "map.pgm", "w.sdf")]
    assert (tmp_path / "w.png").read_bytes().startswith(PNG_MAGIC)
    grid = read_map(tmp_path / "map.yaml")
    assert grid == ground_truth_grid(scenario_warehouse(small_scenario), 0.1)
    ET.parse(tmp_path / "w.sdf")


def test_world_command_writes_only_what_was_asked(tmp_path, small_scenario):
    assert world_command(small_scenario, sdf=tmp_path / "only.sdf") == [tmp_path / "only.sdf"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["only.sdf"]
    assert world_command(small_scenario) == []


@pytest.mark.parametrize("resolution", [0.0, -1.0, float("nan"), 1e-6])
def test_world_command_rejects_a_nonsensical_resolution_before_writing(
    tmp_path, small_scenario, resolution
):
    with pytest.raises(ConfigError, match="resolution"):
        world_command(
            small_scenario,
            png=tmp_path / "w.png",
            map_yaml=tmp_path / "m.yaml",
            resolution_m=resolution,
        )
    assert list(tmp_path.iterdir()) == []


def test_world_command_reports_an_impossible_world_as_a_scenario_error(small_scenario):
    scenario = cosim.load_scenario(
        "warehouse-random", overrides={"world.size_m": [12.0, 12.0], "world.shelf_count": 400}
    )
    with pytest.raises(ScenarioError, match=r"world\.shelf_count"):
        world_command(scenario)

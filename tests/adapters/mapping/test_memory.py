"""The robots' maps' memory (adapters.mapping.memory): every robot's map counts."""

import pytest

import cosim
from adapters.mapping.geometry import map_geometry
from adapters.mapping.memory import (
    CENTROID_BYTES_PER_CELL,
    CHANGES_BYTES_PER_CELL,
    ROBOT_BYTES_PER_CELL,
    SHARED_BYTES_PER_CELL,
    THREAD_BYTES_PER_CELL,
    check_mapping_memory,
    map_shape,
    mapping_bytes,
)
from adapters.world.warehouse import scenario_warehouse
from cosim.core.errors import ConfigError
from cosim.core.memory import Room
from cosim.core.workers import available_cores
from cosim.runner.assembly import check_scenario

GIB = 1 << 30


def mapping(**more):
    return cosim.load_scenario("fleet50", {"mapping.enabled": True, **more})


@pytest.mark.parametrize("resolution_m", [0.05, 0.02, 0.013, 0.3])
def test_the_estimate_counts_the_cells_of_the_maps_the_robots_build(resolution_m):
    scenario = mapping()
    geometry = map_geometry(scenario_warehouse(scenario), resolution_m)
    assert map_shape(scenario.world, resolution_m) == (geometry.width, geometry.height)


def test_every_robot_s_map_counts_and_maps_sent_as_changes_count_more():
    cols, rows = map_shape(mapping().world, 0.05)
    # each thread a run may take (the cores available) has a scratch of its own
    threads = THREAD_BYTES_PER_CELL * available_cores()
    shared = cols * rows * (SHARED_BYTES_PER_CELL + threads)
    walls = ROBOT_BYTES_PER_CELL + CENTROID_BYTES_PER_CELL  # the default refine keeps returns
    assert mapping_bytes(mapping()) == cols * rows * 50 * walls + shared
    on_score = mapping(**{"mapping.refine": "score"})
    assert mapping_bytes(on_score) == cols * rows * 50 * ROBOT_BYTES_PER_CELL + shared
    sent = mapping(**{"mapping.share": "maps", "mapping.refine": "score"})
    per_robot = ROBOT_BYTES_PER_CELL + CHANGES_BYTES_PER_CELL
    assert mapping_bytes(sent) == cols * rows * 50 * per_robot + shared
    assert mapping_bytes(cosim.load_scenario("fleet50")) == 0  # mapping off


def test_a_cell_size_whose_maps_do_not_fit_is_refused_in_one_line_with_one_that_fits(
    monkeypatch,
):
    monkeypatch.setattr("adapters.mapping.memory.available_cores", lambda: 1)  # figures below
    scenario = mapping(**{"mapping.resolution_m": 0.01})
    room = Room(2 * GIB, "MemAvailable in /proc/meminfo")
    with pytest.raises(ConfigError) as caught:
        check_mapping_memory(scenario, room)
    assert str(caught.value) == (
        "preset fleet50: [mapping] resolution_m = 0.01: expected a cell size of at least "
        "0.018 m on this machine: 50 robots' maps of 3,240 x 3,240 cells would take about "
        "6.1 GiB, more than the 2.0 GiB of memory this process has left (MemAvailable in "
        "/proc/meminfo)"
    )
    assert mapping_bytes(scenario, 0.018) <= room.bytes < mapping_bytes(scenario, 0.017)
    check_mapping_memory(mapping(**{"mapping.resolution_m": 0.018}), room)


def test_the_default_cell_size_of_fifty_robots_passes_in_a_gigabyte():
    check_mapping_memory(mapping(), Room(GIB, "ulimit -v"))


def test_the_run_s_checks_refuse_it_before_anything_is_built(monkeypatch):
    monkeypatch.setattr("adapters.mapping.memory.available", lambda: Room(GIB, "ulimit -d"))
    scenario = mapping(**{"mapping.resolution_m": 0.01, "robots.driver": "wander"})
    with pytest.raises(ConfigError, match=r"^preset fleet50: \[mapping\] resolution_m = 0.01: "):
        check_scenario(scenario)

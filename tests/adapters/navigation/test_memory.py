"""The costmaps' memory (adapters.navigation.memory): a cell size that does not fit is one line."""

import resource
import subprocess
import sys

import pytest

import cosim
from adapters.mapping.memory import mapping_bytes
from adapters.navigation.memory import (
    LANDMARK_BYTES_PER_CELL,
    OWN_MAP_BYTES_PER_CELL,
    STATIC_BYTES_PER_CELL,
    check_navigation_memory,
    navigation_bytes,
    static_shape,
)
from adapters.navigation.settings import NavigationConfig
from adapters.world.warehouse import scenario_warehouse
from cosim.core.errors import ConfigError
from cosim.core.memory import Room
from cosim.scenario.sections import WorldConfig
from models.navigation.landmarks import ALT_MIN_CELLS
from models.world.warehouse import ground_truth_grid
from tests.conftest import REPO

GIB = 1 << 30


@pytest.mark.parametrize("preset", ["warehouse-random", "lab-room", "fleet50"])
@pytest.mark.parametrize("resolution_m", [0.1, 0.05, 0.037, 0.2])
def test_the_estimate_counts_the_cells_of_the_grid_the_navigation_builds(preset, resolution_m):
    scenario = cosim.load_scenario(preset)
    grid = ground_truth_grid(scenario_warehouse(scenario), resolution_m)
    rows, cols = grid.data.shape
    assert static_shape(scenario.section(WorldConfig), resolution_m) == (cols, rows)


def test_landmark_fields_count_from_the_size_the_planner_builds_them_at():
    scenario = cosim.load_scenario("warehouse-random")
    small, large = 0.05, 0.04  # 608 x 608 cells: below ALT_MIN_CELLS; 760 x 760: above
    cols, rows = static_shape(scenario.world, small)
    assert cols * rows < ALT_MIN_CELLS
    assert navigation_bytes(scenario, small) == cols * rows * STATIC_BYTES_PER_CELL
    cols, rows = static_shape(scenario.world, large)
    assert cols * rows >= ALT_MIN_CELLS
    per_cell = STATIC_BYTES_PER_CELL + LANDMARK_BYTES_PER_CELL
    assert navigation_bytes(scenario, large) == cols * rows * per_cell


def test_robots_that_map_add_a_costmap_each_over_the_maps_area():
    alone = cosim.load_scenario("warehouse-random", {"navigation.resolution_m": 0.1})
    mapping = cosim.load_scenario(
        "warehouse-random",
        {"navigation.resolution_m": 0.1, "mapping.enabled": True, "mapping.resolution_m": 0.05},
    )
    own = 324 * 324  # 30.4 m and 1 m of margin each side, at 0.1 m
    extra = navigation_bytes(mapping) - navigation_bytes(alone)
    assert extra == own * mapping.robots.count * OWN_MAP_BYTES_PER_CELL


def test_a_cell_size_whose_costmaps_do_not_fit_is_refused_in_one_line_with_one_that_fits():
    scenario = cosim.load_scenario("warehouse-random", {"navigation.resolution_m": 0.0034})
    with pytest.raises(ConfigError) as caught:
        check_navigation_memory(scenario, Room(int(1.5 * GIB), "ulimit -v"))
    assert str(caught.value) == (
        "preset warehouse-random: [navigation] resolution_m = 0.0034: expected a cell size "
        "of at least 0.0083 m on this machine: the costmaps of the 8,942 x 8,942 cell "
        "building would take about 8.9 GiB, more than the 1.5 GiB of memory this process has "
        "left (ulimit -v)"
    )
    fits = scenario.with_section("navigation", NavigationConfig(resolution_m=0.0083))
    check_navigation_memory(fits, Room(int(1.5 * GIB), "ulimit -v"))
    assert navigation_bytes(fits) <= 1.5 * GIB < navigation_bytes(fits, 0.0082)


def test_the_default_cell_size_passes_in_little_memory():
    scenario = cosim.load_scenario("fleet50")
    check_navigation_memory(scenario, Room(64 << 20, "MemAvailable in /proc/meminfo"))


def test_the_costmaps_must_fit_beside_the_robots_maps_and_the_line_says_so():
    scenario = cosim.load_scenario(
        "warehouse-random",
        {"mapping.enabled": True, "mapping.resolution_m": 0.02, "navigation.resolution_m": 0.02},
    )
    maps = mapping_bytes(scenario)
    room = Room(maps + navigation_bytes(scenario) - 1, "the cgroup's memory.max")
    with pytest.raises(
        ConfigError, match=r"has left besides the robots' maps \(.* MiB\) \(the cgr"
    ):
        check_navigation_memory(scenario, room)
    check_navigation_memory(scenario, Room(room.bytes + 1, room.source))


def test_when_no_cell_size_fits_the_line_says_to_shrink_the_fleet_or_the_world():
    scenario = cosim.load_scenario("warehouse-random", {"navigation.resolution_m": 0.5})
    with pytest.raises(
        ConfigError, match=r"expected fewer robots or a smaller world: .* and even "
    ):
        check_navigation_memory(scenario, Room(1000, "ulimit -v"))


def test_cosim_check_refuses_it_under_ulimit_v_instead_of_a_memory_error_mid_run(tmp_path):
    """The report: 611 MiB for one array of the landmark build, a traceback mid-run."""

    def limit() -> None:
        resource.setrlimit(resource.RLIMIT_AS, (int(2.5 * GIB), resource.RLIM_INFINITY))

    command = [sys.executable, "-m", "cosim", "check", "warehouse-random"]
    done = subprocess.run(
        [*command, "--set", "navigation.resolution_m=0.0034"],
        cwd=REPO,
        capture_output=True,
        text=True,
        preexec_fn=limit,
        timeout=300,
    )
    assert done.returncode == 2, done.stderr
    assert done.stderr.count("\n") == 1 and "Traceback" not in done.stderr
    assert done.stderr.startswith(
        "cosim: error: preset warehouse-random: [navigation] resolution_m = 0.0034: expected a "
        "cell size of at least 0.0"
    )
    assert "8.9 GiB, more than the" in done.stderr and "(ulimit -v)" in done.stderr


PEAK = """
import resource, sys
import cosim
scenario = cosim.load_scenario("warehouse-random", {
    "navigation.resolution_m": float(sys.argv[1]), "scenario.duration_s": 1.0,
    "record.bag": "none"})
cosim.run(scenario)
print(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024)
"""


@pytest.mark.slow
def test_the_estimate_grows_at_least_as_fast_as_what_a_run_takes():
    """Two runs a few million cells apart: the peak resident memory grows by no more."""

    def peak(resolution_m: float) -> int:
        done = subprocess.run(
            [sys.executable, "-c", PEAK, str(resolution_m)],
            cwd=REPO,
            capture_output=True,
            text=True,
            check=True,
            timeout=600,
        )
        return int(done.stdout.split()[-1])

    scenario = cosim.load_scenario("warehouse-random")
    coarse, fine = 0.0125, 0.01  # 5.9 and 9.2 million cells, both with landmark fields
    grown = peak(fine) - peak(coarse)
    estimated = navigation_bytes(scenario, fine) - navigation_bytes(scenario, coarse)
    assert grown <= estimated <= 1.5 * grown

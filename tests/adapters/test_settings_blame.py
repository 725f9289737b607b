"""A refused setting names the key that is wrong, not a neighbour of it."""

import pytest

import cosim
from cosim.core.errors import ConfigError
from tests.conftest import cosim_main


def test_a_pick_station_offset_beyond_reach_names_the_offset():
    with pytest.raises(ConfigError, match=r"tasks\.station_offset_m.* 50.*<= 5"):
        cosim.load_scenario("warehouse-random", {"tasks.station_offset_m": 50})


def test_stations_that_fit_nowhere_name_the_offset_and_the_shelves():
    done = cosim_main(
        "check",
        "warehouse-random",
        "--set",
        "tasks.station_offset_m=5",
        "--set",
        "world.size_m=[8.0, 8.0]",
        "--set",
        "world.shelf_count=2",
    )
    assert done.returncode == 2
    assert "world.shelf_count = 2, tasks.station_offset_m = 5: no pick station" in done.stderr
    assert len(done.stderr.strip().splitlines()) == 1


def test_sharing_maps_without_mapping_is_refused_not_ignored():
    with pytest.raises(ConfigError, match=r"mapping\.share.*'scans'.*enabled = false"):
        cosim.load_scenario("warehouse-random", {"mapping.share": "scans"})


def test_turning_mapping_off_in_a_preset_that_shares_nothing_is_fine():
    scenario = cosim.load_scenario("warehouse-mapping", {"mapping.enabled": False})
    assert scenario.mapping.share == "none"

import pytest

import cosim
from cosim.plotting.command import plot_run
from tests.conftest import SMALL
from tests.cosim.plotting.conftest import PNG_MAGIC


@pytest.mark.slow
def test_a_mapping_run_gets_its_maps_and_their_quality_drawn(tmp_path):
    overrides = {
        **SMALL,
        "robots.driver": "navigation",
        "scenario.duration_s": 12.0,
        "mapping.enabled": True,
        "record.bag": "none",
    }
    run = cosim.run(cosim.load_scenario("warehouse-random", overrides=overrides), out=tmp_path)
    names = [p.name for p in plot_run(run.out)]
    assert "maps.png" in names and "map_quality.png" in names
    assert (tmp_path / "figures" / "maps.png").read_bytes().startswith(PNG_MAGIC)


def test_a_run_without_mapping_draws_no_map(tmp_path):
    run = cosim.run(cosim.load_scenario("warehouse-random", overrides=SMALL), out=tmp_path)
    assert "maps.png" not in [p.name for p in plot_run(run.out)]

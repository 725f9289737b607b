import numpy as np
import pytest

import cosim
from adapters.humans.files import TrafficTypes, write_config, write_demand, write_network
from adapters.world.warehouse import scenario_warehouse
from models.humans.aisles import aisle_graph, dock_points, pick_stations
from models.humans.demand import plans

TYPES = TrafficTypes(0.5, 1.2, 0.66, 1.0, 2.3, 1.1, 2.2)


def warehouse(preset="warehouse-rows"):
    return scenario_warehouse(cosim.load_scenario(preset))


@pytest.fixture
def sumo_files(tmp_path):
    """A rows warehouse with 6 workers and 2 forklifts written as SUMO files; the config."""
    return write_files(tmp_path, forklifts=2)


@pytest.fixture
def walkers_only(tmp_path):
    """The same warehouse with 6 workers and no forklift."""
    return write_files(tmp_path, forklifts=0)


def write_files(tmp_path, *, forklifts):
    world = warehouse()
    graph = aisle_graph(world, clearance_m=0.35, spacing_m=1.5)
    stations = pick_stations(world, graph, 12, np.random.default_rng(2))
    docks = dock_points(graph)
    rng = np.random.default_rng(3)
    common = {"duration_s": 60.0, "stay_s": (5.0, 10.0), "rng": rng}
    demand = plans(graph, stations, docks, kind="worker", count=6, speed_mps=1.2, **common)
    demand += plans(
        graph, stations, docks, kind="forklift", count=forklifts, speed_mps=2.2, **common
    )
    lanes = write_network(graph, tmp_path, forklifts=forklifts > 0, inset_m=0.5)
    write_demand(graph, demand, lanes, TYPES, tmp_path)
    return write_config(tmp_path, step_s=0.1, seed=5, end_s=61.0, stripe_width_m=0.5)

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import cosim
from adapters.world.warehouse import scenario_warehouse
from models.errors import ModelError
from models.humans.aisles import aisle_graph, dock_points, pick_stations
from models.humans.demand import STANDING_REACH_M, plans, standing_plans


def _graph():
    world = scenario_warehouse(cosim.load_scenario("warehouse-rows"))
    graph = aisle_graph(world, clearance_m=0.35, spacing_m=1.5)
    return graph, pick_stations(world, graph, 12, np.random.default_rng(2)), dock_points(graph)


def _plans(seed, count=5, duration_s=300.0):
    graph, stations, docks = _graph()
    return plans(
        graph,
        stations,
        docks,
        kind="worker",
        count=count,
        duration_s=duration_s,
        speed_mps=1.2,
        stay_s=(10.0, 40.0),
        rng=np.random.default_rng(seed),
    )


def test_the_same_seed_gives_the_same_plans_and_another_seed_others():
    assert _plans(7) == _plans(7)
    assert _plans(7) != _plans(8)


def test_plans_outlast_the_run_and_visit_stations_and_the_dock():
    _, stations, docks = _graph()
    station_spots = set(zip(stations[0].tolist(), stations[1].tolist(), strict=True))
    dock_spots = set(zip(docks[0].tolist(), docks[1].tolist(), strict=True))
    for plan in _plans(3, duration_s=600.0):
        stays = sum(stage.stay_s for stage in plan.stages)
        assert stays > 0
        walked = len(plan.stages) * 1.0  # at least a metre between spots, conservatively
        assert stays + walked / 1.2 >= 600.0 * 0.5
        spots = {(s.spot.edge, s.spot.offset_m) for s in plan.stages}
        assert spots <= station_spots | dock_spots
        assert (
            min(s.stay_s for s in plan.stages if (s.spot.edge, s.spot.offset_m) in station_spots)
            >= 10.0
        )
    assert len({p.depart_s for p in _plans(3)}) == 5  # departures spread out


def test_standing_workers_stay_at_the_aisle_spot_nearest_their_point_for_the_whole_run():
    graph, _, _ = _graph()
    point = graph.nodes[3] + [0.05, 0.0]
    (plan,) = standing_plans(graph, np.array([point]), 100.0)
    assert plan.stages[0].spot == plan.start
    assert plan.stages[0].stay_s >= 100.0
    x, y = graph.point(plan.start.edge, plan.start.offset_m)
    assert np.hypot(x - point[0], y - point[1]) < 0.1


def test_a_standing_point_far_from_every_aisle_is_refused_naming_it():
    graph, _, _ = _graph()
    with pytest.raises(ModelError) as error:
        standing_plans(graph, np.array([[5.0, 5.0], [-50.0, 5.0]]), 100.0)
    assert error.value.key == "humans.standing[1]"
    assert "nearest is 5" in error.value.expected


@settings(max_examples=60, deadline=None)
@given(x=st.floats(-20.0, 50.0), y=st.floats(-20.0, 50.0))
def test_any_standing_point_stands_within_reach_of_it_or_is_refused(x, y):
    graph, _, _ = _graph()
    try:
        (plan,) = standing_plans(graph, np.array([[x, y]]), 10.0)
    except ModelError as error:
        assert error.key == "humans.standing[0]"
        return
    px, py = graph.point(plan.start.edge, plan.start.offset_m)
    assert np.hypot(px - x, py - y) <= STANDING_REACH_M + 1e-9

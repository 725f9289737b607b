import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import cosim
from adapters.world.warehouse import scenario_warehouse
from models.errors import ModelError
from models.humans.aisles import SAMPLE_M, aisle_graph, dock_points, pick_stations
from models.world.layout import WarehouseSpec
from models.world.warehouse import box_distance, generate_warehouse


def _world(preset, **overrides):
    return scenario_warehouse(cosim.load_scenario(preset, overrides))


def _sampled(graph):
    points = []
    for a, b in graph.edges:
        p, q = graph.nodes[a], graph.nodes[b]
        n = int(np.ceil(np.hypot(*(q - p)) / SAMPLE_M)) + 1
        points.append(p + np.linspace(0, 1, n)[:, None] * (q - p))
    return np.vstack(points)


def _connected(graph):
    seen, todo = {0}, [0]
    while todo:
        node = todo.pop()
        for a, b in graph.edges.tolist():
            for here, there in ((a, b), (b, a)):
                if here == node and there not in seen:
                    seen.add(there)
                    todo.append(there)
    return len(seen) == len(graph.nodes)


@pytest.mark.parametrize("preset", ["warehouse-rows", "warehouse-random", "lab-mixed"])
def test_every_edge_keeps_a_person_clear_of_shelves_and_walls_and_the_graph_is_connected(preset):
    world = _world(preset)
    graph = aisle_graph(world, clearance_m=0.35, spacing_m=1.5)
    points = _sampled(graph)
    assert box_distance(points, world.boxes).min() >= 0.35 - 1e-9
    assert _connected(graph)
    # a lane never reaches beyond the clearance of its own line
    assert (graph.width_m <= 2 * box_distance(points, world.boxes).max()).all()


def test_rows_get_a_line_along_the_centre_of_every_aisle_between_rows():
    world = _world("warehouse-rows")
    graph = aisle_graph(world, clearance_m=0.35, spacing_m=1.5)
    shelves = world.shelves
    # shelf faces running east-west: an aisle lies between consecutive rows' faces
    tops = np.unique(np.round(shelves[:, 3], 6))
    bottoms = np.unique(np.round(shelves[:, 1], 6))
    centres = [(t + b) / 2 for t in tops for b in bottoms if 0 < b - t <= 2.0]
    assert centres, "rows layout without aisles"
    horizontal = graph.edges[
        np.isclose(graph.nodes[graph.edges[:, 0], 1], graph.nodes[graph.edges[:, 1], 1])
    ]
    ys = graph.nodes[horizontal[:, 0], 1]
    for centre in centres:
        assert np.isclose(ys, centre, atol=1e-6).any(), centre


def test_straight_chains_are_one_edge():
    world = _world("warehouse-rows")
    graph = aisle_graph(world, clearance_m=0.35, spacing_m=1.5)
    degree = np.bincount(graph.edges.ravel(), minlength=len(graph.nodes))
    for node in np.flatnonzero(degree == 2):
        a, b = [e for e in graph.edges.tolist() if node in e]
        da = graph.nodes[a[0] if a[1] == node else a[1]] - graph.nodes[node]
        db = graph.nodes[b[0] if b[1] == node else b[1]] - graph.nodes[node]
        assert abs(da[0] * db[1] - da[1] * db[0]) > 1e-9  # a corner, not a straight run


def test_pick_stations_lie_beside_shelves_outside_the_dock_and_docks_in_the_south():
    world = _world("warehouse-rows")
    graph = aisle_graph(world, clearance_m=0.35, spacing_m=1.5)
    edges, offsets = pick_stations(world, graph, 50, np.random.default_rng(3))
    points = np.array([graph.point(e, o) for e, o in zip(edges, offsets, strict=True)])
    assert (points[:, 1] > world.dock_depth_m).all()
    reach = graph.width_m[edges] / 2 + 1.0  # within 1 m beyond the lane's edge
    assert (box_distance(points, world.shelves).min(axis=1) <= reach + 1e-9).all()
    dock_edges, dock_offsets = dock_points(graph)
    docks = np.array([graph.point(e, o) for e, o in zip(dock_edges, dock_offsets, strict=True)])
    assert docks[:, 1].max() <= graph.nodes[:, 1].min() + 0.5 + 1e-9
    same = pick_stations(world, graph, 50, np.random.default_rng(3))
    assert (same[0] == edges).all() and (same[1] == offsets).all()


def test_a_room_too_narrow_for_a_person_is_refused_naming_the_key():
    world = _world("lab-mixed")
    with pytest.raises(ModelError) as error:
        aisle_graph(world, clearance_m=5.0, spacing_m=1.5)
    assert error.value.key == "humans.worker_radius_m"


def test_nearest_snaps_points_onto_the_closest_edge():
    world = _world("warehouse-rows")
    graph = aisle_graph(world, clearance_m=0.35, spacing_m=1.5)
    edges, offsets, gaps = graph.nearest(graph.nodes[:5] + 0.01)
    for e, o, node, gap in zip(edges, offsets, graph.nodes[:5], gaps, strict=True):
        assert np.hypot(*(np.array(graph.point(e, o)) - node)) < 0.05
        assert gap < 0.02


@settings(max_examples=15, deadline=None)
@given(
    seed=st.integers(0, 10_000),
    shelves=st.integers(0, 30),
    aisle=st.floats(1.0, 3.0),
    spacing=st.floats(0.5, 4.0),
)
def test_random_warehouses_give_connected_graphs_clear_of_every_box(seed, shelves, aisle, spacing):
    spec = WarehouseSpec(
        size_m=(20.0, 16.0),
        layout="random",
        shelf_count=shelves,
        shelf_size_m=(2.0, 0.8),
        aisle_width_m=aisle,
        robot_count=2,
    )
    try:
        world = generate_warehouse(spec, np.random.default_rng(seed))
    except ModelError:
        return  # shelves that do not fit: the world generator's business
    graph = aisle_graph(world, clearance_m=0.35, spacing_m=spacing)
    assert box_distance(_sampled(graph), world.boxes).min() >= 0.35 - 1e-9
    assert _connected(graph)
    assert len(graph.edges) == len({tuple(e) for e in graph.edges.tolist()})

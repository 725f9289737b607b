"""The map and markers as RViz and Foxglove draw them."""

import math

import pytest
from rosbags.typesys import Stores, get_typestore

from cosim.core.messages import (
    Marker,
    MarkerAction,
    MarkerArray,
    MarkerType,
    OccupancyGrid,
    std,
)
from cosim.core.messages.decoding import decode_tree

HUMBLE = get_typestore(Stores.ROS2_HUMBLE)


def _fields(kind, data: bytes) -> dict[str, object]:
    return dict(zip(kind.names(), decode_tree(kind, data), strict=True))


def test_a_grid_whose_cells_are_not_width_times_height_is_refused_naming_both():
    with pytest.raises(ValueError, match=r"occupancy grid of 3 x 2 cells got 5 values"):
        OccupancyGrid(0, "map", 0.05, 3, 2, 0.0, 0.0, bytes(5))


def test_a_grid_is_loaded_at_its_stamp_with_an_unrotated_origin():
    grid = OccupancyGrid(23, "map", 0.05, 3, 2, -0.2, -0.4, bytes([0, 100, 255, 0, 0, 100]))
    fields = _fields(std.OCCUPANCY_GRID, grid.to_cdr())
    load_time, resolution, width, height, origin = fields["info"]  # type: ignore[misc]
    assert fields["header"] == (23, "map") and load_time == 23
    assert resolution == pytest.approx(0.05) and (width, height) == (3, 2)
    assert origin == ((-0.2, -0.4, 0.0), (0.0, 0.0, 0.0, 1.0))
    assert fields["data"] == bytes([0, 100, 255, 0, 0, 100])  # 255 is int8 -1: unknown


def test_a_grid_decodes_back_to_itself():
    grid = OccupancyGrid(23, "map", 0.5, 2, 2, 1.0, -1.0, bytes([0, 100, 255, 0]))
    assert OccupancyGrid.from_cdr(grid.to_cdr()) == grid


@pytest.mark.parametrize("member", [*MarkerType, *MarkerAction], ids=lambda m: m.name)
def test_marker_shapes_and_actions_have_the_values_of_visualization_msgs(member):
    constants = {name: value for name, _, value in HUMBLE.fielddefs[std.MARKER.ros_type][0]}
    assert constants[member.name] == member.value


MARKERS = (
    Marker("shelves", 3, MarkerType.CUBE, x_m=1.0, y_m=2.0, z_m=0.9, scale_m=(2.0, 0.8, 1.8)),
    Marker(
        "robots",
        0,
        MarkerType.CYLINDER,
        frame_id="robot_1/base_link",
        color=(0.5, 0.25, 1.0, 0.75),
        frame_locked=True,
    ),
    Marker("tasks", 0, MarkerType.CYLINDER, action=MarkerAction.DELETEALL),
    Marker("tasks", 1_000_003, MarkerType.TEXT_VIEW_FACING, text="task 3: robot_1"),
)


def test_every_marker_carries_the_arrays_stamp_and_lives_forever():
    (markers,) = decode_tree(std.MARKER_ARRAY, MarkerArray(7, MARKERS).to_cdr())
    for decoded, marker in zip(markers, MARKERS, strict=True):
        fields = dict(zip(std.MARKER.names(), decoded, strict=True))
        assert fields["header"] == (7, marker.frame_id)
        assert fields["lifetime"] == 0
        assert (fields["ns"], fields["id"], fields["type"], fields["action"]) == (
            marker.ns,
            marker.marker_id,
            marker.kind,
            marker.action,
        )
        assert fields["points"] == [] and fields["colors"] == [] and fields["mesh_resource"] == ""


def test_a_marker_pose_is_planar_with_a_height():
    (markers,) = decode_tree(std.MARKER_ARRAY, MarkerArray(7, MARKERS[:1]).to_cdr())
    pose = dict(zip(std.MARKER.names(), markers[0], strict=True))["pose"]
    assert pose == ((1.0, 2.0, 0.9), (0.0, 0.0, 0.0, 1.0))


def test_markers_decode_back_with_their_enums():
    back = MarkerArray.from_cdr(MarkerArray(7, MARKERS).to_cdr())
    assert back == MarkerArray(7, MARKERS)
    assert back.markers[2].action is MarkerAction.DELETEALL
    assert back.markers[0].kind is MarkerType.CUBE


def test_a_turned_marker_keeps_its_yaw():
    turned = Marker("m", 1, MarkerType.SPHERE, yaw_rad=2.0)
    (back,) = MarkerArray.from_cdr(MarkerArray(1, (turned,)).to_cdr()).markers
    assert back.yaw_rad == pytest.approx(2.0)
    assert math.isclose(back.x_m, 0.0)

import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest
import yaml

from adapters.world.files import (
    FREE_THRESH,
    OCCUPIED_THRESH,
    SHELF_HEIGHT_M,
    WALL_HEIGHT_M,
    read_map,
    write_map,
    write_sdf,
)
from cosim.core.errors import ConfigError, ExportError
from cosim.plotting.world import world_figure
from models.geometry.occupancy import FREE, OCCUPIED, UNKNOWN, OccupancyGrid
from models.world.warehouse import Warehouse, WarehouseSpec, generate_warehouse, ground_truth_grid

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


@pytest.fixture
def warehouse() -> Warehouse:
    return generate_warehouse(
        WarehouseSpec(size_m=(14.0, 12.0), shelf_count=5, robot_count=3),
        np.random.default_rng(7),
    )


@pytest.fixture
def mixed_grid() -> OccupancyGrid:
    """A 3 x 4 grid holding every cell value, asymmetric so that flips show."""
    data = np.array(
        [
            [FREE, FREE, OCCUPIED, UNKNOWN],
            [OCCUPIED, FREE, FREE, FREE],
            [UNKNOWN, UNKNOWN, FREE, OCCUPIED],
        ],
        dtype=np.int8,
    )
    return OccupancyGrid(resolution_m=0.05, origin_xy_m=(-0.2, -1.35), data=data)


def _nav2_trinary(pixel: int, negate: bool = False) -> int:
    """nav2_map_server's loadMapFromFile for one grey pixel in trinary mode."""
    shade = pixel / 255.0
    occ = shade if negate else 1.0 - shade
    if occ > OCCUPIED_THRESH:
        return OCCUPIED
    if occ < FREE_THRESH:
        return FREE
    return UNKNOWN


def _a_file_in_the_way(tmp_path: Path) -> Path:
    """A regular file used as a folder: unwritable even for root."""
    blocker = tmp_path / "blocker"
    blocker.write_text("not a folder")
    return blocker


def test_a_map_round_trips_through_pgm_and_yaml(tmp_path, mixed_grid):
    write_map(mixed_grid, tmp_path / "map.yaml")
    assert read_map(tmp_path / "map.yaml") == mixed_grid


def test_a_warehouse_map_round_trips_through_pgm_and_yaml(tmp_path, warehouse):
    grid = ground_truth_grid(warehouse, 0.05)
    write_map(grid, tmp_path / "maps" / "hall.yaml")
    assert read_map(tmp_path / "maps" / "hall.yaml") == grid


def test_the_pgm_is_binary_p5_with_the_highest_y_row_first(tmp_path, mixed_grid):
    yaml_path, pgm_path = write_map(mixed_grid, tmp_path / "map.yaml")
    assert (yaml_path, pgm_path) == (tmp_path / "map.yaml", tmp_path / "map.pgm")
    raw = pgm_path.read_bytes()
    header = b"P5\n4 3\n255\n"
    assert raw.startswith(header)
    assert len(raw) == len(header) + 4 * 3
    pixels = np.frombuffer(raw[len(header) :], dtype=np.uint8).reshape(3, 4)
    assert pixels.tolist() == [[205, 205, 254, 0], [0, 254, 254, 254], [254, 254, 0, 205]]


def test_the_yaml_has_exactly_the_map_server_keys(tmp_path, mixed_grid):
    write_map(mixed_grid, tmp_path / "map.yaml")
    doc = yaml.safe_load((tmp_path / "map.yaml").read_text())
    assert doc == {
        "image": "map.pgm",
        "mode": "trinary",
        "resolution": 0.05,
        "origin": [-0.2, -1.35, 0.0],
        "negate": 0,
        "occupied_thresh": 0.65,
        "free_thresh": FREE_THRESH,
    }


def test_written_pixels_load_in_nav2_as_the_cells_they_came_from(tmp_path, mixed_grid):
    _, pgm_path = write_map(mixed_grid, tmp_path / "map.yaml")
    pixels = np.frombuffer(pgm_path.read_bytes()[-12:], dtype=np.uint8).reshape(3, 4)
    loaded = [[_nav2_trinary(int(p)) for p in row] for row in pixels[::-1]]
    assert loaded == mixed_grid.data.tolist()


def test_the_unknown_grey_would_load_as_free_under_the_old_nav2_threshold():
    # why free_thresh is 0.196 and not 0.25: (255 - 205) / 255 = 0.196 < 0.25
    assert (255 - 205) / 255 < 0.25
    assert _nav2_trinary(205) == UNKNOWN


def test_read_map_follows_negate_thresholds_and_header_comments(tmp_path):
    pixels = np.array([[0, 100, 200, 255]], dtype=np.uint8)
    (tmp_path / "img.pgm").write_bytes(b"P5\n# made by hand\n4 1\n255\n" + pixels.tobytes())
    (tmp_path / "m.yaml").write_text(
        "# a third-party map\nimage: img.pgm\nresolution: 0.1\norigin: [1, 2, 0]\n"
        "negate: 1\noccupied_thresh: 0.7\nfree_thresh: 0.3\n"
    )
    grid = read_map(tmp_path / "m.yaml")
    # negate: occupancy = value / 255 -> 0.0, 0.39, 0.78, 1.0
    assert grid.data.tolist() == [[FREE, UNKNOWN, OCCUPIED, OCCUPIED]]
    assert grid.origin_xy_m == (1.0, 2.0)
    assert grid.resolution_m == 0.1


@pytest.mark.parametrize(
    ("text", "word"),
    [
        ("mode: scale\n", "mode"),
        ("origin: [0, 0, 1.57]\n", "origin"),
        ("origin: [0, 0]\n", "origin"),
        ("resolution: fine\n", "resolution"),
    ],
)
def test_read_map_rejects_what_it_cannot_load_naming_the_key(tmp_path, mixed_grid, text, word):
    write_map(mixed_grid, tmp_path / "map.yaml")
    lines = (tmp_path / "map.yaml").read_text().splitlines(keepends=True)
    key = text.split(":")[0]
    lines = [text if line.startswith(key + ":") else line for line in lines]
    if not any(line.startswith(key + ":") for line in lines):
        lines.append(text)
    (tmp_path / "map.yaml").write_text("".join(lines))
    with pytest.raises(ConfigError, match=word):
        read_map(tmp_path / "map.yaml")


def test_read_map_rejects_an_image_that_is_not_binary_pgm(tmp_path, mixed_grid):
    write_map(mixed_grid, tmp_path / "map.yaml")
    (tmp_path / "map.pgm").write_bytes(b"P2\n1 1\n255\n0\n")
    with pytest.raises(ConfigError, match="P5"):
        read_map(tmp_path / "map.yaml")


def test_the_sdf_has_one_static_box_model_per_wall_and_shelf(tmp_path, warehouse):
    path = write_sdf(warehouse, tmp_path / "world.sdf", world_name="hall")
    root = ET.parse(path).getroot()
    assert root.tag == "sdf"
    assert root.get("version") == "1.6"
    world = root.find("world")
    assert world is not None and world.get("name") == "hall"
    assert world.find("light[@name='sun']") is not None
    assert world.find("model[@name='ground_plane']/link/collision/geometry/plane") is not None
    models = {m.get("name"): m for m in world.findall("model")}
    expected = [(f"wall_{i}", b, WALL_HEIGHT_M) for i, b in enumerate(warehouse.walls)]
    expected += [(f"shelf_{i}", b, SHELF_HEIGHT_M) for i, b in enumerate(warehouse.shelves)]
    assert set(models) == {name for name, _, _ in expected} | {"ground_plane"}
    for name, (xmin, ymin, xmax, ymax), height in expected:
        model = models[name]
        assert model.findtext("static") == "true"
        pose = [float(v) for v in model.findtext("pose").split()]
        centre = [(xmin + xmax) / 2, (ymin + ymax) / 2, height / 2, 0, 0, 0]
        assert pose == pytest.approx(centre, abs=1e-6)
        for part in ("collision", "visual"):
            size = model.findtext(f"link/{part}/geometry/box/size")
            assert [float(v) for v in size.split()] == pytest.approx(
                [xmax - xmin, ymax - ymin, height], abs=1e-6
            )


def test_the_world_figure_is_a_png(tmp_path, warehouse):
    path = world_figure(warehouse, tmp_path / "figures" / "world.png", title="hall")
    data = path.read_bytes()
    assert data.startswith(PNG_MAGIC)
    assert len(data) > 1000


def test_unwritable_paths_are_export_errors_naming_the_path(tmp_path, warehouse, mixed_grid):
    blocked = _a_file_in_the_way(tmp_path)
    writers = [
        lambda: write_map(mixed_grid, blocked / "map.yaml"),
        lambda: write_sdf(warehouse, blocked / "world.sdf"),
        lambda: world_figure(warehouse, blocked / "world.png", title="x"),
    ]
    for write in writers:
        with pytest.raises(ExportError, match="blocker"):
            write()


def test_a_map_yaml_named_like_its_image_is_refused(tmp_path, mixed_grid):
    with pytest.raises(ExportError, match=r"\.yaml"):
        write_map(mixed_grid, tmp_path / "map.pgm")

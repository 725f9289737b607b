"""World files: ROS ``map_server`` maps (PGM + YAML) and Gazebo SDF worlds.

The map format is the one ``nav2_map_server`` reads (``nav2_map_server/src/map_io.cpp``,
``loadMapYaml`` and ``loadMapFromFile``): a YAML file naming an image next to it, the
cell size, the ``map`` pose of the image's bottom-left corner and two thresholds. In
``trinary`` mode every pixel's occupancy ``p = (255 - value) / 255`` (``p = value / 255``
when ``negate`` is set) becomes occupied if ``p > occupied_thresh``, free if
``p < free_thresh``, and unknown otherwise; image rows run top to bottom, i.e. from the
highest y down.

Pixel values are those of nav2's ``map_saver`` (occupied 0, free 254, unknown 205). For
205 to load back as unknown, ``free_thresh`` must lie below ``(255 - 205) / 255 = 0.19608``:
we write 0.196, as ROS 1's ``map_saver`` always did and nav2's does since
ros-navigation/navigation2 PR #5278 (with the older nav2 default 0.25, unknown space
reloads as free).
"""

from __future__ import annotations

import json
import math
import xml.etree.ElementTree as ET
from collections.abc import Iterable
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

# PyYAML reads map files written by other tools (comments, quotes, block lists)
import yaml

from cosim.core.errors import ConfigError, ExportError
from models.errors import ModelError
from models.geometry.occupancy import FREE, OCCUPIED, UNKNOWN, OccupancyGrid
from models.world.warehouse import Warehouse

OCCUPIED_PIXEL = 0
"""PGM value of an occupied cell (black)."""
FREE_PIXEL = 254
"""PGM value of a free cell (white)."""
UNKNOWN_PIXEL = 205
"""PGM value of an unknown cell (grey)."""
OCCUPIED_THRESH = 0.65
"""Occupancy above which a pixel loads as occupied."""
FREE_THRESH = 0.196
"""Occupancy below which a pixel loads as free (just under the unknown pixel's 0.19608)."""

DEFAULT_RESOLUTION_M = 0.05
"""Map cell size (m/cell) when none is given: nav2's usual 5 cm."""

WALL_HEIGHT_M = 2.5
"""Height of the walls in SDF worlds (m)."""
SHELF_HEIGHT_M = 2.0
"""Height of the shelves in SDF worlds (m)."""


def _write(path: Path, content: bytes) -> Path:
    """Write ``content`` to ``path`` (creating its folder), as an :class:`ExportError`."""
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_bytes(content)
    except OSError as error:
        raise ExportError(f"{path}: cannot write: {error.strerror or error}") from None
    return path


def _yaml_string(text: str) -> str:
    """``text`` as a YAML scalar: plain when YAML reads it back unchanged, else quoted."""
    if yaml.safe_load(text) == text and text.strip() == text and "\n" not in text:
        return text
    return json.dumps(text)  # a JSON string is a valid double-quoted YAML scalar


def pgm_bytes(grid: OccupancyGrid) -> bytes:
    """The grid as a binary PGM (P5, maxval 255), highest-y row first."""
    pixels = np.full(grid.data.shape, UNKNOWN_PIXEL, dtype=np.uint8)
    pixels[grid.data == FREE] = FREE_PIXEL
    pixels[grid.data >= OCCUPIED] = OCCUPIED_PIXEL
    header = f"P5\n{grid.width} {grid.height}\n255\n".encode("ascii")
    return header + np.ascontiguousarray(pixels[::-1]).tobytes()


def write_map(grid: OccupancyGrid, yaml_path: Path) -> list[Path]:
    """Write a ``map_server`` map: ``yaml_path`` and a PGM image beside it.

    The image is ``yaml_path`` with the suffix ``.pgm``; its bottom-left corner is at
    the grid origin in ``map``. Cells are written trinary: occupied (100) black, free (0)
    white, anything else (unknown, or a probability between) grey.

    Args:
        grid: the occupancy grid (frame ``map``).
        yaml_path: where to write the YAML file.

    Returns:
        The paths written: the YAML file, then the image.

    Raises:
        ExportError: naming the path if a file cannot be written.
    """
    yaml_path = Path(yaml_path)
    image_path = yaml_path.with_suffix(".pgm")
    if image_path == yaml_path:
        raise ExportError(f"{yaml_path}: expected a .yaml file name for the map metadata")
    x0, y0 = grid.origin_xy_m
    # repr gives the shortest text that reads back as the same float
    text = (
        f"image: {_yaml_string(image_path.name)}\n"
        "mode: trinary\n"
        f"resolution: {float(grid.resolution_m)!r}\n"
        f"origin: [{float(x0)!r}, {float(y0)!r}, 0.0]\n"
        "negate: 0\n"
        f"occupied_thresh: {OCCUPIED_THRESH}\n"
        f"free_thresh: {FREE_THRESH}\n"
    )
    _write(image_path, pgm_bytes(grid))
    _write(yaml_path, text.encode("utf-8"))
    return [yaml_path, image_path]


def _read_pgm(path: Path) -> npt.NDArray[np.float64]:
    """Pixels of a binary PGM, rows top to bottom, scaled by maxval to [0, 1]."""
    try:
        raw = path.read_bytes()
    except OSError as error:
        raise ConfigError(f"{path}: cannot read the map image: {error.strerror}") from None
    fields: list[bytes] = []
    pos = 0
    while len(fields) < 4:  # magic, width, height, maxval; '#' starts a comment line
        while pos < len(raw) and raw[pos : pos + 1].isspace():
            pos += 1
        if raw[pos : pos + 1] == b"#":
            pos = raw.find(b"\n", pos) + 1 or len(raw)
            continue
        start = pos
        while pos < len(raw) and not raw[pos : pos + 1].isspace() and raw[pos : pos + 1] != b"#":
            pos += 1
        if start == pos:
            break
        fields.append(raw[start:pos])
    if len(fields) < 4 or fields[0] != b"P5" or not all(f.isdigit() for f in fields[1:]):
        raise ConfigError(f"{path}: expected a binary PGM image (P5 width height maxval)")
    width, height, maxval = (int(f) for f in fields[1:])
    if not 0 < maxval < 65536:
        raise ConfigError(f"{path}: maxval = {maxval}: expected 1..65535")
    dtype = np.dtype(np.uint8) if maxval < 256 else np.dtype(">u2")
    body = raw[pos + 1 :]  # exactly one whitespace byte follows maxval
    count = width * height
    if len(body) < count * dtype.itemsize:
        raise ConfigError(f"{path}: {len(body)} bytes of pixels: expected {count * dtype.itemsize}")
    pixels = np.frombuffer(body, dtype=dtype, count=count).reshape(height, width)
    shade: npt.NDArray[np.float64] = pixels.astype(np.float64) / maxval
    return shade


def _number(path: Path, doc: dict[str, Any], key: str) -> float:
    value = doc.get(key)
    try:
        number = float(value)  # type: ignore[arg-type]  # anything else is reported below
    except (TypeError, ValueError):
        number = math.nan
    if not math.isfinite(number):
        raise ConfigError(f"{path}: {key} = {value!r}: expected a number")
    return number


def read_map(yaml_path: Path) -> OccupancyGrid:
    """Load a ``map_server`` map as ``nav2_map_server`` does in ``trinary`` mode.

    Args:
        yaml_path: the map's YAML file; a relative ``image`` is taken beside it.

    Returns:
        The grid (frame ``map``), cells 0 free, 100 occupied, -1 unknown.

    Raises:
        ConfigError: naming the file and key for a missing or malformed key, a mode other
            than ``trinary``, a rotated origin, or an image that is not a binary PGM.
    """
    yaml_path = Path(yaml_path)
    try:
        doc = yaml.safe_load(yaml_path.read_text(encoding="utf-8"))
    except OSError as error:
        raise ConfigError(f"{yaml_path}: cannot read the map: {error.strerror}") from None
    except yaml.YAMLError as error:
        raise ConfigError(f"{yaml_path}: not YAML: {error}".replace("\n", " ")) from None
    if not isinstance(doc, dict):
        raise ConfigError(f"{yaml_path}: expected a mapping of map_server keys")
    image = doc.get("image")
    if not isinstance(image, str) or not image:
        raise ConfigError(f"{yaml_path}: image = {image!r}: expected an image file name")
    mode = doc.get("mode", "trinary")
    if mode != "trinary":
        raise ConfigError(f"{yaml_path}: mode = {mode!r}: expected 'trinary'")
    origin = doc.get("origin")
    if not isinstance(origin, list) or len(origin) != 3:
        raise ConfigError(f"{yaml_path}: origin = {origin!r}: expected [x, y, yaw]")
    x0, y0, yaw = (_number(yaml_path, {"origin": v}, "origin") for v in origin)
    if yaw != 0.0:
        raise ConfigError(f"{yaml_path}: origin yaw = {yaw!r}: expected 0.0 (an axis-aligned map)")
    resolution = _number(yaml_path, doc, "resolution")
    occupied_thresh = _number(yaml_path, doc, "occupied_thresh")
    free_thresh = _number(yaml_path, doc, "free_thresh")
    negate = bool(doc.get("negate", 0))
    shade = _read_pgm(yaml_path.parent / image)
    occupancy = shade if negate else 1.0 - shade
    data = np.full(occupancy.shape, UNKNOWN, dtype=np.int8)
    data[occupancy > occupied_thresh] = OCCUPIED
    data[occupancy < free_thresh] = FREE
    try:
        return OccupancyGrid(resolution_m=resolution, origin_xy_m=(x0, y0), data=data[::-1])
    except ModelError as error:
        raise ConfigError(f"{yaml_path}: {error}") from None


def _num(value: float) -> str:
    """A length for SDF text: micrometre precision without trailing zeros."""
    text = f"{float(value):.6f}".rstrip("0").rstrip(".")
    return "0" if text in ("", "-0") else text


def _sub(parent: ET.Element, tag: str, text: str | None = None, **attrib: str) -> ET.Element:
    element = ET.SubElement(parent, tag, attrib)
    if text is not None:
        element.text = text
    return element


def _box_model(
    world: ET.Element, name: str, box: Iterable[float], height_m: float, rgb: str
) -> None:
    """A static model with one box link, its pose at the box centre (frame ``map``)."""
    xmin, ymin, xmax, ymax = (float(v) for v in box)
    model = _sub(world, "model", name=name)
    _sub(model, "static", "true")
    centre = ((xmin + xmax) / 2, (ymin + ymax) / 2, height_m / 2)
    _sub(model, "pose", " ".join(_num(v) for v in centre) + " 0 0 0")
    link = _sub(model, "link", name="link")
    size = " ".join(_num(v) for v in (xmax - xmin, ymax - ymin, height_m))
    for kind in ("collision", "visual"):
        part = _sub(link, kind, name=kind)
        _sub(_sub(_sub(part, "geometry"), "box"), "size", size)
        if kind == "visual":
            material = _sub(part, "material")
            _sub(material, "ambient", f"{rgb} 1")
            _sub(material, "diffuse", f"{rgb} 1")


def sdf_text(warehouse: Warehouse, *, world_name: str = "warehouse") -> str:
    """The warehouse as a Gazebo SDF 1.6 world (frame ``map`` = Gazebo world frame)."""
    sdf = ET.Element("sdf", version="1.6")
    world = _sub(sdf, "world", name=world_name)
    sun = _sub(world, "light", type="directional", name="sun")
    _sub(sun, "cast_shadows", "true")
    _sub(sun, "pose", "0 0 10 0 0 0")
    _sub(sun, "diffuse", "0.8 0.8 0.8 1")
    _sub(sun, "specular", "0.2 0.2 0.2 1")
    attenuation = _sub(sun, "attenuation")
    for tag, value in (("range", "1000"), ("constant", "0.9"), ("linear", "0.01")):
        _sub(attenuation, tag, value)
    _sub(attenuation, "quadratic", "0.001")
    _sub(sun, "direction", "-0.5 0.1 -0.9")

    # the ground plane is centred on the hall and 10 m larger than it, so nothing the
    # robots can reach is over the edge
    xmin, ymin, xmax, ymax = warehouse.bounds
    ground = _sub(world, "model", name="ground_plane")
    _sub(ground, "static", "true")
    _sub(ground, "pose", f"{_num((xmin + xmax) / 2)} {_num((ymin + ymax) / 2)} 0 0 0 0")
    link = _sub(ground, "link", name="link")
    for kind in ("collision", "visual"):
        part = _sub(link, kind, name=kind)
        plane = _sub(_sub(part, "geometry"), "plane")
        _sub(plane, "normal", "0 0 1")
        _sub(plane, "size", f"{_num(xmax - xmin + 10)} {_num(ymax - ymin + 10)}")
        if kind == "visual":
            _sub(part, "cast_shadows", "false")
            material = _sub(part, "material")
            _sub(material, "ambient", "0.8 0.8 0.8 1")
            _sub(material, "diffuse", "0.8 0.8 0.8 1")

    for i, box in enumerate(warehouse.walls):
        _box_model(world, f"wall_{i}", box, WALL_HEIGHT_M, "0.5 0.5 0.5")
    for i, box in enumerate(warehouse.shelves):
        _box_model(world, f"shelf_{i}", box, SHELF_HEIGHT_M, "0.8 0.5 0.2")
    ET.indent(sdf, space="  ")
    return '<?xml version="1.0" encoding="utf-8"?>\n' + ET.tostring(sdf, encoding="unicode") + "\n"


def write_sdf(warehouse: Warehouse, sdf_path: Path, *, world_name: str = "warehouse") -> Path:
    """Write the warehouse as a Gazebo SDF 1.6 world.

    One static model per wall (``wall_0..3``, 2.5 m high) and shelf (``shelf_0..``,
    2.0 m high), each a box link with collision and visual posed at the box centre,
    plus a ground plane and a directional sun.

    Args:
        warehouse: the generated world (frame ``map``, which becomes the SDF world frame).
        sdf_path: where to write the ``.sdf`` file.
        world_name: the ``<world name=...>``.

    Raises:
        ExportError: naming the path if the file cannot be written.
    """
    return _write(Path(sdf_path), sdf_text(warehouse, world_name=world_name).encode("utf-8"))

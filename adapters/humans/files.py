"""SUMO's files for a run: the aisle network (through ``netconvert``), the demand, a config.

Everything is written into one folder (the run folder's ``sumo/``), so a user can open
the run's traffic with ``sumo-gui -c humans.sumocfg`` and see what the robots saw.

The network keeps the ``map`` frame (``--offset.disable-normalization``): SUMO's x, y are
cosim's. Each aisle edge ``e<k>`` is one lane centred on the aisle line, as wide as the
aisle less ``inset_m`` (a person's width), open to pedestrians and to the robots' mirrors
(vClass ``custom1``). With forklifts (vClass ``custom2``), they drive on it and on its
reverse twin ``r<k>``, which is open to pedestrians too: a lane closed to them would split
the junctions' walking areas (SUMO lets people cross a road only on a crossing).
netconvert lays the twins side by side, each right of the line, so with forklifts each
twin is half the aisle wide: like traffic on a road, forklifts keep right; people walk on
either half, and SUMO's people see one another and the robots only on the same half.
"""

from __future__ import annotations

import shutil
import subprocess
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

from cosim.core.errors import BridgeError
from models.humans.aisles import AisleGraph
from models.humans.demand import Plan, Spot

NETWORK = "aisles.net.xml"
ROUTES = "humans.rou.xml"
CONFIG = "humans.sumocfg"
ROBOT_CLASS = "custom1"
FORKLIFT_CLASS = "custom2"
MIN_LANE_M = 0.3
"""Narrowest lane written, however tight the aisle (m)."""
JUNCTION_RADIUS_M = 0.3
"""Corner radius of junctions: aisles meet at right angles, nobody needs a wide turn (m)."""
NETCONVERT_TIMEOUT_S = 120.0


@dataclass(frozen=True)
class TrafficTypes:
    """Sizes and speeds of the SUMO types (m, m/s)."""

    worker_width_m: float
    worker_speed_mps: float
    robot_size_m: float
    robot_speed_mps: float
    forklift_length_m: float
    forklift_width_m: float
    forklift_speed_mps: float


def sumo_tool(name: str) -> Path:
    """The path of a SUMO program (``sumo``, ``netconvert``) from the eclipse-sumo package.

    Raises:
        BridgeError: if it is not installed.
    """
    try:
        import sumo  # the eclipse-sumo wheel: its binaries live under SUMO_HOME/bin

        candidate = Path(sumo.SUMO_HOME) / "bin" / name
        if candidate.is_file():
            return candidate
    except ImportError:
        pass
    found = shutil.which(name)
    if found is None:
        raise BridgeError(
            f"SUMO's {name} is not installed: expected the eclipse-sumo package "
            "(a dependency of cosim; reinstall with `make venv`)"
        )
    return Path(found)


def write_network(
    graph: AisleGraph, folder: Path, *, forklifts: bool, inset_m: float = 0.0
) -> dict[str, float]:
    """Write the plain network and convert it to ``aisles.net.xml`` with netconvert.

    Args:
        graph: the aisle graph; an edge's lane is its ``width_m`` less ``inset_m``.
        folder: where the files go.
        forklifts: add the reverse twins forklifts need.
        inset_m: how much narrower than the free aisle a lane is (m): SUMO puts a
            pedestrian's centre anywhere up to the lane's edge, so a lane narrower by a
            person's width keeps people off the shelves' faces.

    Returns:
        The length of each lane by edge id (m): junctions take a little of every edge,
        so positions along an aisle are mapped with :func:`lane_position`.

    Raises:
        BridgeError: if netconvert fails (its last error line is in the message).
    """
    folder.mkdir(parents=True, exist_ok=True)
    nodes = ET.Element("nodes")
    for i, (x, y) in enumerate(graph.nodes.tolist()):
        ET.SubElement(nodes, "node", id=f"n{i}", x=f"{x:.3f}", y=f"{y:.3f}", type="priority")
    edges = ET.Element("edges")
    forward = f"pedestrian {ROBOT_CLASS}" + (f" {FORKLIFT_CLASS}" if forklifts else "")
    for k, ((a, b), width) in enumerate(
        zip(graph.edges.tolist(), graph.width_m.tolist(), strict=True)
    ):
        # netconvert lays two opposite edges side by side, each right of the line: with
        # forklifts, each takes half the aisle
        lane = max(width - inset_m, MIN_LANE_M)
        lane = lane / 2 if forklifts else lane
        common = {"numLanes": "1", "width": f"{lane:.3f}", "spreadType": "center"}
        ET.SubElement(
            edges, "edge", id=f"e{k}", attrib={"from": f"n{a}", "to": f"n{b}", "allow": forward}
        ).attrib.update(common)
        if forklifts:
            ET.SubElement(
                edges,
                "edge",
                id=f"r{k}",
                attrib={"from": f"n{b}", "to": f"n{a}", "allow": f"pedestrian {FORKLIFT_CLASS}"},
            ).attrib.update(common)
    _write_xml(nodes, folder / "aisles.nod.xml")
    _write_xml(edges, folder / "aisles.edg.xml")
    command = [
        str(sumo_tool("netconvert")),
        "--node-files", "aisles.nod.xml",
        "--edge-files", "aisles.edg.xml",
        "--output-file", NETWORK,
        "--offset.disable-normalization", "true",
        "--walkingareas", "true",
        "--default.junctions.radius", f"{JUNCTION_RADIUS_M}",
        "--precision", "3",
        "--no-warnings", "true",
    ]  # fmt: skip
    try:
        done = subprocess.run(
            command,
            cwd=folder,
            capture_output=True,
            text=True,
            timeout=NETCONVERT_TIMEOUT_S,
            check=False,
        )
    except (OSError, subprocess.TimeoutExpired) as error:
        raise BridgeError(
            f"SUMO's netconvert could not build {folder / NETWORK}: {error}"
        ) from None
    if done.returncode != 0 or not (folder / NETWORK).is_file():
        lines = [line for line in done.stderr.splitlines() if line.strip()]
        lines = [line for line in lines if line.startswith("Error")] or lines
        raise BridgeError(
            f"SUMO's netconvert could not build {folder / NETWORK}: "
            f"{lines[-1] if lines else f'exit status {done.returncode}'}"
        )
    return lane_lengths(folder / NETWORK)


def lane_lengths(network: Path) -> dict[str, float]:
    """The length of the first lane of every normal edge of a SUMO network (m).

    Raises:
        BridgeError: if the file is not a SUMO network.
    """
    try:
        root = ET.parse(network).getroot()
    except (OSError, ET.ParseError) as error:
        raise BridgeError(f"{network}: not a readable SUMO network ({error})") from None
    lengths: dict[str, float] = {}
    for edge in root.iter("edge"):
        if edge.get("function") is not None:
            continue  # internal edges, walking areas
        lane = edge.find("lane")
        if lane is not None:
            lengths[edge.attrib["id"]] = float(lane.attrib["length"])
    return lengths


def lane_position(graph: AisleGraph, spot: Spot, lanes: dict[str, float]) -> float:
    """The position on lane ``e<k>`` of a spot on graph edge ``k`` (m).

    Junctions shorten every lane at both ends by about the same amount; the position is
    shifted by half the difference and kept 0.1 m inside the lane.
    """
    full = float(graph.length_m[spot.edge])
    lane = lanes[f"e{spot.edge}"]
    position = spot.offset_m - (full - lane) / 2
    return min(max(position, 0.1), max(lane - 0.1, 0.1))


def write_demand(
    graph: AisleGraph,
    plans: list[Plan],
    lanes: dict[str, float],
    types: TrafficTypes,
    folder: Path,
) -> None:
    """Write ``humans.rou.xml``: the types, and each worker's and forklift's plan."""
    routes = ET.Element("routes")
    ET.SubElement(
        routes,
        "vType",
        id="worker",
        vClass="pedestrian",
        width=f"{types.worker_width_m:.3f}",
        length="0.3",
        maxSpeed=f"{types.worker_speed_mps:.3f}",
        speedDev="0.1",
    )
    ET.SubElement(
        routes,
        "vType",
        id="robot",
        vClass=ROBOT_CLASS,
        width=f"{types.robot_size_m:.3f}",
        length=f"{types.robot_size_m:.3f}",
        maxSpeed=f"{max(types.robot_speed_mps, 0.01):.3f}",
        minGap="0.1",
    )
    ET.SubElement(
        routes,
        "vType",
        id="forklift",
        vClass=FORKLIFT_CLASS,
        width=f"{types.forklift_width_m:.3f}",
        length=f"{types.forklift_length_m:.3f}",
        maxSpeed=f"{types.forklift_speed_mps:.3f}",
        accel="1.0",
        decel="2.0",
        minGap="0.5",
    )
    for plan in sorted(plans, key=lambda p: (p.depart_s, p.name)):
        if plan.kind == "worker":
            _person(routes, graph, plan, lanes)
        else:
            _forklift(routes, graph, plan, lanes)
    _write_xml(routes, folder / ROUTES)


def _person(routes: ET.Element, graph: AisleGraph, plan: Plan, lanes: dict[str, float]) -> None:
    start = lane_position(graph, plan.start, lanes)
    person = ET.SubElement(
        routes,
        "person",
        id=plan.name,
        type="worker",
        depart=f"{plan.depart_s:.1f}",
        departPos=f"{start:.2f}",
    )
    edge = f"e{plan.start.edge}"
    for stage in plan.stages:
        target = f"e{stage.spot.edge}"
        position = lane_position(graph, stage.spot, lanes)
        if stage.spot != plan.start or stage is not plan.stages[0]:
            ET.SubElement(
                person,
                "walk",
                attrib={"from": edge, "to": target, "arrivalPos": f"{position:.2f}"},
            )
        if stage.stay_s > 0:
            ET.SubElement(
                person,
                "stop",
                lane=f"{target}_0",
                endPos=f"{position:.2f}",
                duration=f"{stage.stay_s:.1f}",
                actType="picking",
            )
        edge = target


def _forklift(routes: ET.Element, graph: AisleGraph, plan: Plan, lanes: dict[str, float]) -> None:
    trip = ET.SubElement(
        routes,
        "trip",
        id=plan.name,
        type="forklift",
        depart=f"{plan.depart_s:.1f}",
        departPos=f"{lane_position(graph, plan.start, lanes):.2f}",
        attrib={"from": f"e{plan.start.edge}", "to": f"e{plan.stages[-1].spot.edge}"},
    )
    for stage in plan.stages:
        position = lane_position(graph, stage.spot, lanes)
        ET.SubElement(
            trip,
            "stop",
            lane=f"e{stage.spot.edge}_0",
            endPos=f"{position:.2f}",
            duration=f"{max(stage.stay_s, 1.0):.1f}",
        )


def write_config(
    folder: Path,
    *,
    step_s: float,
    seed: int,
    end_s: float,
    stripe_width_m: float = 0.65,
    jam_time_s: float = 300.0,
) -> Path:
    """Write ``humans.sumocfg``: network, demand and every option that shapes the run.

    Args:
        folder: where the network and demand are.
        step_s: SUMO's step (s).
        seed: SUMO's random seed.
        end_s: when SUMO stops (s).
        stripe_width_m: the striping model's lateral stripe (m; SUMO's default 0.65).
        jam_time_s: a pedestrian blocked this long walks on regardless (s; SUMO's 300).

    Returns:
        The config's path: ``sumo-gui -c`` on it replays the run's people, given the
        robots' positions (which only the co-simulation has).
    """
    config = ET.Element("configuration")
    inputs = ET.SubElement(config, "input")
    ET.SubElement(inputs, "net-file", value=NETWORK)
    ET.SubElement(inputs, "route-files", value=ROUTES)
    timing = ET.SubElement(config, "time")
    ET.SubElement(timing, "begin", value="0")
    ET.SubElement(timing, "end", value=f"{end_s:g}")
    ET.SubElement(timing, "step-length", value=f"{step_s:g}")
    processing = ET.SubElement(config, "processing")
    ET.SubElement(processing, "time-to-teleport", value="-1")
    ET.SubElement(processing, "pedestrian.striping.stripe-width", value=f"{stripe_width_m:g}")
    ET.SubElement(processing, "pedestrian.striping.jamtime", value=f"{jam_time_s:g}")
    random = ET.SubElement(config, "random_number")
    ET.SubElement(random, "seed", value=str(seed))
    _write_xml(config, folder / CONFIG)
    return folder / CONFIG


def _write_xml(root: ET.Element, path: Path) -> None:
    ET.indent(root)
    ET.ElementTree(root).write(path, encoding="utf-8", xml_declaration=True)

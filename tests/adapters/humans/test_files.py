import subprocess
import xml.etree.ElementTree as ET

import numpy as np
import pytest

from adapters.humans import files
from adapters.humans.files import lane_lengths, sumo_tool, write_network
from cosim.core.errors import BridgeError
from models.humans.aisles import aisle_graph

from .conftest import warehouse


def test_the_network_keeps_cosims_frame_and_one_centred_lane_per_aisle_edge(tmp_path):
    graph = aisle_graph(warehouse(), clearance_m=0.35, spacing_m=1.5)
    lanes = write_network(graph, tmp_path, forklifts=False)
    assert set(lanes) == {f"e{k}" for k in range(len(graph.edges))}
    root = ET.parse(tmp_path / "aisles.net.xml").getroot()
    junctions = {j.get("id"): j for j in root.iter("junction")}
    for i, (x, y) in enumerate(graph.nodes[:10]):
        j = junctions[f"n{i}"]
        assert float(j.get("x")) == pytest.approx(x, abs=1e-3)
        assert float(j.get("y")) == pytest.approx(y, abs=1e-3)
    # junctions shorten a lane by less than a lane width at each end
    lengths = graph.length_m
    for k in range(len(graph.edges)):
        assert lengths[k] - 2 * graph.width_m.max() - 0.1 <= lanes[f"e{k}"] <= lengths[k] + 1e-3


def test_forklifts_get_a_reverse_edge_that_people_do_not_walk_on(tmp_path):
    graph = aisle_graph(warehouse(), clearance_m=0.35, spacing_m=1.5)
    write_network(graph, tmp_path, forklifts=True)
    root = ET.parse(tmp_path / "aisles.edg.xml").getroot()
    allow = {e.get("id"): e.get("allow") for e in root.iter("edge")}
    assert "pedestrian" in allow["e0"] and files.FORKLIFT_CLASS in allow["e0"]
    assert files.FORKLIFT_CLASS in allow["r0"] and files.ROBOT_CLASS not in allow["r0"]


def test_sumo_gui_could_open_the_written_config(sumo_files):
    done = subprocess.run(
        [str(sumo_tool("sumo")), "-c", str(sumo_files), "--end", "5", "--no-step-log"],
        capture_output=True,
        text=True,
        timeout=60,
        check=False,
    )
    assert done.returncode == 0, done.stderr


def test_a_missing_netconvert_is_one_line_naming_it(tmp_path, monkeypatch):
    monkeypatch.setattr(files, "sumo_tool", lambda name: tmp_path / "no" / name)
    graph = aisle_graph(warehouse(), clearance_m=0.35, spacing_m=1.5)
    with pytest.raises(BridgeError) as error:
        write_network(graph, tmp_path, forklifts=False)
    assert "netconvert" in str(error.value)
    assert "\n" not in str(error.value)


def test_netconvert_refusing_the_network_reports_its_own_error_line(tmp_path):
    graph = aisle_graph(warehouse(), clearance_m=0.35, spacing_m=1.5)
    broken = type(graph)(graph.nodes, np.array([[0, 10_000]]), graph.width_m[:1])
    with pytest.raises(BridgeError, match=r"netconvert could not build .*: Error"):
        write_network(broken, tmp_path, forklifts=False)


def test_a_file_that_is_not_a_network_is_refused_naming_it(tmp_path):
    bad = tmp_path / "bad.net.xml"
    bad.write_text("<net>garbage")
    with pytest.raises(BridgeError, match=r"bad\.net\.xml: not a readable SUMO network"):
        lane_lengths(bad)

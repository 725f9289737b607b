"""People and forklifts in a run's figures."""

from dataclasses import replace

import numpy as np
import pytest
from matplotlib.colors import to_rgb
from PIL import Image

import cosim
from cosim.plotting.people import FORKLIFT_COLOR, PERSON_COLOR, PeopleLayer
from cosim.plotting.rundata import load_run
from cosim.plotting.trajectories import snapshots_figure, trajectories_figure

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def people_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("people") / "run"
    scenario = cosim.load_scenario(
        "warehouse-humans",
        {"scenario.duration_s": 8.0, "humans.workers": 6, "humans.forklifts": 1},
    )
    cosim.run(scenario, out=out)
    return load_run(out)


def _pixels_like(png, color, tolerance=0.08):
    rgb = np.asarray(Image.open(png).convert("RGB"), dtype=float) / 255
    return int((np.abs(rgb - np.array(to_rgb(color))).max(axis=2) < tolerance).sum())


def test_the_run_data_carries_the_humans_table(people_run):
    humans = people_run.humans
    assert humans is not None
    assert set(humans["kind"]) == {"person", "forklift"}
    assert humans["id"].nunique() == 7


@pytest.mark.parametrize("draw", ["snapshots", "trajectories"])
def test_people_and_forklifts_are_drawn_and_a_run_without_them_has_neither(
    people_run, tmp_path, draw
):
    without = replace(people_run, humans=None)
    for run, name in ((people_run, "with.png"), (without, "without.png")):
        if draw == "snapshots":
            snapshots_figure(run, [4.0, 7.9], tmp_path / name)
        else:
            trajectories_figure(run, tmp_path / name)
    assert _pixels_like(tmp_path / "with.png", FORKLIFT_COLOR) > 50
    assert _pixels_like(tmp_path / "without.png", FORKLIFT_COLOR) == 0
    assert _pixels_like(tmp_path / "with.png", PERSON_COLOR) > _pixels_like(
        tmp_path / "without.png", PERSON_COLOR
    )


def test_a_snapshot_shows_everyone_at_the_latest_sample_before_its_time(people_run):
    from matplotlib.figure import Figure

    layer = PeopleLayer(Figure().add_subplot(), people_run)
    assert layer.at(0.05) is None  # before SUMO's first step
    rows = layer.at(5.05)
    assert rows is not None
    assert np.allclose(rows["t_s"], 5.0)
    assert len(rows) == 7
    people, forklifts = layer.show(5.05)
    assert len(people.get_paths()) == 6 and len(forklifts.get_paths()) == 1

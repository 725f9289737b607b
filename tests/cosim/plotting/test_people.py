"""People and forklifts (``tables/humans``) drawn over the world, where SUMO had them."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from matplotlib.colors import to_rgba
from matplotlib.figure import Figure

from cosim.plotting.people import (
    FORKLIFT_COLOR,
    PERSON_COLOR,
    TRACK_ALPHA,
    PeopleLayer,
    PeopleSamples,
    draw_tracks,
    people_handles,
    people_inks,
)
from cosim.plotting.rundata import RunData, load_run

# two workers and a forklift heading north, sampled at 1 s and 2 s
HUMANS = pd.DataFrame(
    {
        "t_s": [2.0, 1.0, 1.0, 1.0, 2.0, 2.0],
        "id": ["p1", "p1", "p2", "f1", "p2", "f1"],
        "kind": ["person", "person", "person", "forklift", "person", "forklift"],
        "x_m": [1.5, 1.0, 3.0, 6.0, 3.5, 6.0],
        "y_m": [1.0, 1.0, 3.0, 5.0, 3.0, 6.0],
        "yaw_rad": [0.0, 0.0, 0.0, math.pi / 2, 0.0, math.pi / 2],
    }
)


@pytest.fixture(scope="module")
def people_run(waypoint_run: Path) -> RunData:
    return dataclasses.replace(load_run(waypoint_run), humans=HUMANS)


@pytest.fixture(scope="module")
def nobody(waypoint_run: Path) -> RunData:
    return load_run(waypoint_run)


def test_everyone_is_where_the_latest_sample_at_or_before_the_time_had_them(people_run):
    samples = PeopleSamples(people_run)
    assert samples.at(0.99) is None  # before the first sample
    first = samples.at(1.0)
    assert first is not None and first["t_s"].tolist() == [1.0, 1.0, 1.0]
    assert sorted(first["id"]) == ["f1", "p1", "p2"]
    later = samples.at(1.999)
    assert later is not None and (later["t_s"] == 1.0).all()
    last = samples.at(60.0)
    assert last is not None and (last["t_s"] == 2.0).all() and len(last) == 3


def test_a_run_without_people_has_no_one_at_any_time(nobody):
    samples = PeopleSamples(nobody)
    assert samples.at(1.0) is None and samples.discs(1.0).shape == (0, 3)


def test_the_lidar_sees_a_worker_as_a_disc_and_a_forklift_as_two(people_run):
    samples = PeopleSamples(people_run)
    radius = people_run.scenario.humans.worker_radius_m
    length, width = people_run.scenario.humans.forklift_size_m
    discs = samples.discs(1.0)
    np.testing.assert_allclose(discs[:2], [[1.0, 1.0, radius], [3.0, 3.0, radius]])
    cover = math.hypot(length / 4, width / 2)
    # the forklift heads north: its discs lie a quarter of its length ahead and behind
    np.testing.assert_allclose(
        discs[2:], [[6.0, 5.0 + length / 4, cover], [6.0, 5.0 - length / 4, cover]]
    )


def test_workers_are_dark_discs_and_forklifts_yellow_rectangles_turned_to_their_heading(people_run):
    layer = PeopleLayer(Figure().add_subplot(), people_run)
    people, forklifts = layer.show(2.0)
    assert len(people.get_paths()) == 2 and len(forklifts.get_paths()) == 1
    assert to_rgba(PERSON_COLOR) == pytest.approx(tuple(people.get_facecolor()[0]))
    assert to_rgba(FORKLIFT_COLOR) == pytest.approx(tuple(forklifts.get_facecolor()[0]))
    length, width = people_run.scenario.humans.forklift_size_m
    corners = forklifts.get_paths()[0].vertices[:4]
    # heading north: the long side along y
    assert np.ptp(corners[:, 1]) == pytest.approx(length)
    assert np.ptp(corners[:, 0]) == pytest.approx(width)
    assert corners.mean(axis=0) == pytest.approx([6.0, 6.0])
    people, forklifts = layer.show(0.5)
    assert len(people.get_paths()) == 0 and len(forklifts.get_paths()) == 0


def test_everyone_s_track_is_a_thin_light_line_in_their_colour(people_run, nobody):
    ax = Figure().add_subplot()
    draw_tracks(ax, people_run)
    (tracks,) = ax.collections
    np.testing.assert_allclose(tracks.get_segments()[0], [[6.0, 5.0], [6.0, 6.0]])  # f1
    np.testing.assert_allclose(
        tracks.get_segments()[1], [[1.0, 1.0], [1.5, 1.0]]
    )  # p1, in time order
    assert tracks.get_colors()[0][:3] == pytest.approx(to_rgba(FORKLIFT_COLOR)[:3])
    assert tracks.get_colors()[1][:3] == pytest.approx(to_rgba(PERSON_COLOR)[:3])
    assert tracks.get_alpha() == TRACK_ALPHA
    empty = Figure().add_subplot()
    draw_tracks(empty, nobody)
    assert len(empty.collections) == 0


def test_the_legend_counts_the_people_and_names_the_forklifts_only_when_there_are_some(
    people_run, nobody
):
    assert [h.get_label() for h in people_handles(people_run)] == [
        "2 people (SUMO)", "forklifts (SUMO)",
    ]  # fmt: skip
    workers_only = dataclasses.replace(people_run, humans=HUMANS[HUMANS["kind"] == "person"])
    assert [h.get_label() for h in people_handles(workers_only)] == ["2 people (SUMO)"]
    assert people_handles(nobody) == []
    assert people_inks(people_run) == [PERSON_COLOR, FORKLIFT_COLOR]
    assert people_inks(nobody) == []

"""People and forklifts in a run's figures, where tables/humans puts them."""

from dataclasses import replace

import numpy as np
import pytest
from matplotlib.colors import to_rgb
from matplotlib.figure import Figure
from PIL import Image, ImageSequence

import cosim
from cosim.plotting import trajectories
from cosim.plotting.animation import animation_gif
from cosim.plotting.people import FORKLIFT_COLOR, PERSON_COLOR, PeopleLayer
from cosim.plotting.rundata import RunData, load_run

pytestmark = pytest.mark.slow

HUMANS = {"scenario.duration_s": 10.0, "humans.workers": 3, "humans.forklifts": 1}
CLEAR_M = 1.2
"""A person this far from every robot, task station and other person is drawn unhidden (m)."""


@pytest.fixture(scope="module")
def people_run(tmp_path_factory) -> RunData:
    out = tmp_path_factory.mktemp("people") / "run"
    cosim.run(cosim.load_scenario("warehouse-humans", HUMANS), out=out)
    return load_run(out)


def _pixels_like(rgb, color, tolerance=0.08):
    return int((np.abs(rgb - np.array(to_rgb(color))).max(axis=-1) < tolerance).sum())


def _png(path):
    return np.asarray(Image.open(path).convert("RGB"), dtype=float) / 255


def _drawn(monkeypatch, draw):
    """Call ``draw`` and return the figures it saved, rendered as RGB arrays, with their axes."""
    saved: list[Figure] = []
    original = trajectories.save_png

    def keep(figure, png_path, **kwargs):
        saved.append(figure)
        return original(figure, png_path, **kwargs)

    monkeypatch.setattr(trajectories, "save_png", keep)
    draw()
    (figure,) = saved
    figure.canvas.draw()
    rgb = np.asarray(figure.canvas.buffer_rgba())[..., :3] / 255
    return figure, rgb


def _at(rgb, ax, x_m, y_m):
    """The pixel of ``rgb`` where ``ax`` draws the point (x_m, y_m) of frame ``map``."""
    px, py = ax.transData.transform((x_m, y_m))
    return rgb[rgb.shape[0] - 1 - round(float(py)), round(float(px))]


def _unhidden(run: RunData, t_s: float):
    """Who is drawn at ``t_s`` (latest sample at or before it) clear of robots, tasks, others."""
    humans = run.humans
    assert humans is not None
    latest = humans["t_s"][humans["t_s"] <= t_s + 1e-9].max()
    rows = humans[humans["t_s"] == latest]
    track = run.track
    i = track.index_at(t_s)
    others = [np.column_stack([track.x_m[i], track.y_m[i]])]
    if run.tasks is not None:
        others.append(run.tasks[["x_m", "y_m"]].to_numpy())
    clear = []
    for row in rows.itertuples():
        xy = np.array([row.x_m, row.y_m])
        near = [np.linalg.norm(p - xy, axis=1).min(initial=np.inf) for p in others]
        people = np.linalg.norm(rows[["x_m", "y_m"]].to_numpy() - xy, axis=1)
        if min(near) > CLEAR_M and np.sort(people)[1] > CLEAR_M:
            clear.append(row)
    return clear


def _color_of(kind):
    return FORKLIFT_COLOR if kind == "forklift" else PERSON_COLOR


def _close(pixel, color, tolerance=0.08):
    return bool(np.abs(pixel - np.array(to_rgb(color))).max() < tolerance)


def test_the_run_data_carries_the_humans_table(people_run):
    humans = people_run.humans
    assert humans is not None
    assert set(humans["kind"]) == {"person", "forklift"}
    assert humans["id"].nunique() == 4


@pytest.mark.slow
def test_the_trajectories_figure_shows_everyone_at_their_last_place_and_not_without_them(
    people_run, tmp_path, monkeypatch
):
    end = float(people_run.track.t_s[-1])
    shown = _unhidden(people_run, end)
    assert len(shown) >= 2
    without = replace(people_run, humans=None)
    figure, rgb = _drawn(
        monkeypatch, lambda: trajectories.trajectories_figure(people_run, tmp_path / "with.png")
    )
    figure_none, rgb_none = _drawn(
        monkeypatch, lambda: trajectories.trajectories_figure(without, tmp_path / "without.png")
    )
    for row in shown:
        assert _close(_at(rgb, figure.axes[0], row.x_m, row.y_m), _color_of(row.kind)), row
        pixel = _at(rgb_none, figure_none.axes[0], row.x_m, row.y_m)
        assert not _close(pixel, _color_of(row.kind)), row
    # the written files: people's colours only in the figure with people
    with_png, without_png = _png(tmp_path / "with.png"), _png(tmp_path / "without.png")
    assert _pixels_like(with_png, FORKLIFT_COLOR) > 50
    assert _pixels_like(without_png, FORKLIFT_COLOR) == 0
    assert _pixels_like(with_png, PERSON_COLOR) > _pixels_like(without_png, PERSON_COLOR)


@pytest.mark.slow
def test_each_snapshot_shows_everyone_where_they_were_at_its_time(
    people_run, tmp_path, monkeypatch
):
    times = [3.0, 9.5]
    without = replace(people_run, humans=None)
    figure, rgb = _drawn(
        monkeypatch,
        lambda: trajectories.snapshots_figure(people_run, times, tmp_path / "with.png"),
    )
    figure_none, rgb_none = _drawn(
        monkeypatch,
        lambda: trajectories.snapshots_figure(without, times, tmp_path / "without.png"),
    )
    checked = 0
    for k, t in enumerate(times):
        t_panel = float(people_run.track.t_s[people_run.track.index_at(t)])
        for row in _unhidden(people_run, t_panel):
            assert _close(_at(rgb, figure.axes[k], row.x_m, row.y_m), _color_of(row.kind)), row
            pixel = _at(rgb_none, figure_none.axes[k], row.x_m, row.y_m)
            assert not _close(pixel, _color_of(row.kind)), row
            checked += 1
    assert checked >= 3


@pytest.mark.slow
def test_the_animation_shows_people_only_in_a_run_with_people(people_run, tmp_path):
    without = replace(people_run, humans=None)
    for run, name in ((people_run, "with.gif"), (without, "without.gif")):
        animation_gif(run, tmp_path / name, max_frames=20)

    def forklift_pixels(path):
        frames = ImageSequence.Iterator(Image.open(path))
        return [_pixels_like(np.asarray(f.convert("RGB")) / 255, FORKLIFT_COLOR) for f in frames]

    assert max(forklift_pixels(tmp_path / "with.gif")) > 20
    assert max(forklift_pixels(tmp_path / "without.gif")) == 0


def test_a_snapshot_shows_everyone_at_the_latest_sample_before_its_time(people_run):
    layer = PeopleLayer(Figure().add_subplot(), people_run)
    assert layer.at(0.05) is None  # before SUMO's first step
    rows = layer.at(5.05)
    assert rows is not None
    assert np.allclose(rows["t_s"], 5.0)
    assert len(rows) == 4
    people, forklifts = layer.show(5.05)
    assert len(people.get_paths()) == 3 and len(forklifts.get_paths()) == 1


def test_the_redrawn_lidar_beams_stop_at_people_as_the_run_s_lidar_did(people_run):
    from cosim.plotting.people import PeopleSamples
    from cosim.plotting.rays import LidarRays
    from models.geometry.angles import wrap_angles

    samples = PeopleSamples(people_run)
    track = people_run.track
    checked = 0
    for robot in range(len(track.robots)):
        rays = LidarRays(people_run, robot, max_rays=360)
        for i in range(0, len(track.t_s), 10):
            origin, ends, _ = rays.cast(i)
            discs = samples.discs(float(track.t_s[i]))
            if not len(ends) or not len(discs):
                continue
            reach = np.hypot(*(ends - origin).T)
            for x, y, r in discs:
                gap = np.hypot(x - origin[0], y - origin[1])
                if not r + 0.5 < gap < rays.range_max_m - 1:
                    continue
                bearings = np.arctan2(ends[:, 1] - origin[1], ends[:, 0] - origin[0])
                toward = np.arctan2(y - origin[1], x - origin[0])
                beam = int(np.argmin(np.abs(wrap_angles(bearings - toward))))
                assert reach[beam] <= gap - r + 0.05  # stopped at (or before) the person
                checked += 1
    assert checked > 0

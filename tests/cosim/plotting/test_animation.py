import itertools

from PIL import Image

from cosim.plotting.animation import MAX_FRAMES, animation_gif, frame_indices
from cosim.plotting.rays import LidarRays
from cosim.plotting.rundata import load_run

MAX_GIF_BYTES = 3_000_000


def test_frames_are_capped_and_spread_evenly_from_the_first_pose_to_the_last():
    frames = frame_indices(1200)
    assert len(frames) == MAX_FRAMES
    assert frames[0] == 0 and frames[-1] == 1199
    assert max(b - a for a, b in itertools.pairwise(frames)) <= 9
    assert frame_indices(30) == list(range(30))


def test_the_gif_has_at_most_max_frames_frames_and_a_bounded_size(task_run, tmp_path):
    path = animation_gif(load_run(task_run), tmp_path / "run.gif", max_frames=12)
    assert path.stat().st_size < MAX_GIF_BYTES
    with Image.open(path) as gif:
        assert gif.format == "GIF"
        assert gif.n_frames == 12
        assert gif.info["duration"] == 100
        assert max(gif.size) < 1000


def test_every_pose_sample_of_a_short_run_is_a_frame(waypoint_run, tmp_path):
    run = load_run(waypoint_run)
    path = animation_gif(run, tmp_path / "run.gif")
    with Image.open(path) as gif:
        assert gif.n_frames == len(run.track.t_s) < MAX_FRAMES


def test_lidar_rays_stop_at_what_they_hit_and_reach_range_max_otherwise(task_run):
    run = load_run(task_run)
    rays = LidarRays(run, 0, max_rays=45)
    origin, ends, hit = rays.cast(0)
    assert len(ends) == 45  # the 90 beams of the scenario, every second one
    lengths = ((ends - origin) ** 2).sum(axis=1) ** 0.5
    assert (lengths[hit] < run.scenario.lidar.range_max_m).all()
    assert (abs(lengths[~hit] - run.scenario.lidar.range_max_m) < 1e-9).all()
    assert hit.any()  # a 12 m hall: walls within 10 m in most directions

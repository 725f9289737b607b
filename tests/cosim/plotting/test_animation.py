import itertools

from PIL import Image

from cosim.plotting.animation import MAX_FRAMES, animation_gif, frame_indices
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

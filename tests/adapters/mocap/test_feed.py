import math
import threading
import time

import pytest

from adapters.mocap.feed import MotionCaptureFeed, mock_bodies, quaternion_yaw
from cosim.core.errors import BridgeError

BODIES = {"r1": (1.0, 2.0, 0.5), "r2": (3.0, 4.0, -1.0)}
F32 = 1e-6  # the library hands poses over as float32


def mock_feed(bodies: list[str]) -> MotionCaptureFeed:
    return MotionCaptureFeed("mock", bodies=bodies, options={"rigid_bodies": mock_bodies(BODIES)})


def gather(feed: MotionCaptureFeed, wanted: int, within_s: float = 2.0) -> list:
    """Drain ``feed`` until ``wanted`` bodies were seen or ``within_s`` passed."""
    samples: list = []
    deadline = time.monotonic() + within_s
    while time.monotonic() < deadline and len({s[1] for s in samples}) < wanted:
        samples += feed.drain()
        time.sleep(0.01)
    return samples


def test_the_mock_system_delivers_both_bodies_at_their_planar_poses_within_two_seconds():
    with mock_feed(["r1", "r2"]) as feed:
        before = time.time_ns()
        samples = gather(feed, 2)
        assert {s[1] for s in samples} == {"r1", "r2"}
        for stamp_ns, body, x, y, yaw in samples:
            assert (x, y, yaw) == pytest.approx(BODIES[body], abs=F32)
            assert before <= stamp_ns <= time.time_ns()
        stamps = [s[0] for s in samples]
        assert stamps == sorted(stamps)  # arrival order
        assert feed.missing_bodies() == []
        assert feed.frames >= 1 and feed.occluded == 0


def test_a_body_asked_for_but_not_in_the_system_is_missing():
    with mock_feed(["r1", "ghost", "r2"]) as feed:
        samples = gather(feed, 2)
        assert feed.missing_bodies() == ["ghost"]
        assert "ghost" not in {s[1] for s in samples}


def test_a_body_in_the_system_but_not_asked_for_is_not_delivered():
    with mock_feed(["r2"]) as feed:
        samples = gather(feed, 1)
        time.sleep(0.05)
        samples += feed.drain()
        assert samples and {s[1] for s in samples} == {"r2"}


def test_an_unknown_system_is_a_bridge_error_naming_it():
    with pytest.raises(BridgeError, match=r"motion capture 'qualisis'.*expected one of vicon"):
        MotionCaptureFeed("qualisis", bodies=["r1"])


def test_closing_a_feed_stops_its_thread():
    before = set(threading.enumerate())
    with mock_feed(["r1"]) as feed:
        started = [t for t in threading.enumerate() if t not in before]
        assert len(started) == 1 and started[0].is_alive()
        assert gather(feed, 1)
    deadline = time.monotonic() + 1.5
    while started[0].is_alive() and time.monotonic() < deadline:
        time.sleep(0.01)
    assert not started[0].is_alive()
    feed.drain()  # whatever the last frame left
    time.sleep(0.1)
    assert feed.drain() == []  # nothing arrives once closed


@pytest.mark.parametrize("yaw", [0.0, 0.5, -1.0, 3.0, -3.0, math.pi / 2])
def test_mock_bodies_hold_the_heading_they_are_given(yaw):
    name, values = mock_bodies({"b": (0.0, 0.0, yaw)}).rstrip(")").split("(")
    x, y, z, w, qx, qy, qz = (float(v) for v in values.split(","))
    assert name == "b" and (x, y, z) == (0.0, 0.0, 0.0)
    assert quaternion_yaw(w, qx, qy, qz) == pytest.approx(yaw, abs=1e-12)

import math
import time

import pytest

from adapters.mocap.feed import MotionCaptureFeed, mock_bodies
from cosim.core.errors import BridgeError


def test_the_mock_system_delivers_its_bodies_with_their_planar_poses():
    rigid = mock_bodies({"r1": (1.0, 2.0, 0.5), "r2": (3.0, 4.0, -1.0)})
    with MotionCaptureFeed(
        "mock", bodies=["r1", "r2", "r9"], options={"rigid_bodies": rigid}
    ) as feed:
        deadline = time.monotonic() + 2.0
        seen: dict[str, tuple[float, float, float]] = {}
        while time.monotonic() < deadline and len(seen) < 2:
            for _t, body, x, y, yaw in feed.drain():
                seen[body] = (x, y, yaw)
            time.sleep(0.02)
        assert seen["r1"] == pytest.approx((1.0, 2.0, 0.5), abs=1e-6)
        assert seen["r2"] == pytest.approx((3.0, 4.0, -1.0), abs=1e-6)
        assert feed.missing_bodies() == ["r9"]
    assert not feed._thread.is_alive()


def test_an_unknown_mocap_system_is_named_with_the_known_ones():
    with pytest.raises(BridgeError, match=r"'nosuch'.*vicon"):
        MotionCaptureFeed("nosuch", bodies=["r1"])


def test_mock_bodies_are_written_as_the_library_reads_them():
    assert mock_bodies({"a": (1, 2, math.pi)}).startswith("a(1.0,2.0,0.0,")

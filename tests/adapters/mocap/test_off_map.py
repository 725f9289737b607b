"""A replayed track that leaves the room: recorded once, never passed on, never a traceback."""

from pathlib import Path

import pandas as pd
import pytest

from tests.conftest import cosim_main


def leaving_track(path: Path) -> Path:
    """robot_1 drives north from its start (0.6, 0.6) for 2 s, then west through the wall."""
    rows = ["t_s,x_m,y_m,yaw_rad"]
    for k in range(60):
        x, y = (0.6, 0.6 + 0.04 * k) if k < 20 else (0.6 - 0.04 * (k - 20), 1.36)
        rows.append(f"{k * 0.1:.1f},{x:.3f},{y:.3f},1.5708")
    path.write_text("\n".join(rows) + "\n")
    return path


@pytest.mark.slow
def test_a_replay_that_leaves_the_room_records_it_once_and_holds_the_robot(tmp_path: Path):
    track = leaving_track(tmp_path / "leave.csv")
    out = tmp_path / "run"
    done = cosim_main(
        "run",
        "lab-room",
        "--duration-s",
        "8",
        "--quiet",
        "--set",
        "robots.driver=navigation",
        "--set",
        "navigation.goals=[[3.3, 2.0], [0.7, 4.6]]",
        "--set",
        "mocap.source=bag",
        "--set",
        f"mocap.file={track}",
        "--set",
        'mocap.bodies=[["robot_1", ""]]',
        "--out",
        str(out),
    )
    assert (done.returncode, done.stderr) == (0, "")
    events = pd.read_parquet(out / "tables" / "events.parquet")
    off = events[events.kind == "pose_off_map"]
    assert list(off.source) == ["robot_1"]  # once, not once per pose
    # x = 0.6 - 0.04 k first passes the wall's outer face (-0.2 m) at k = 41, 4.1 s
    assert off.t_s.iloc[0] == pytest.approx(4.1)
    assert off.detail.iloc[0] == (
        "pose (-0.24, 1.36) m outside the world [-0.2, 4.2] x [-0.2, 8.2] m: rejected, the "
        "robot holds its last pose"
    )
    mocap = pd.read_parquet(out / "tables" / "mocap.parquet")
    assert list(mocap.event) == ["off_map", "stale"]  # its navigation stopped it
    poses = pd.read_parquet(out / "tables" / "poses.parquet")
    twin = poses[(poses.robot == "robot_1") & (poses.t_s >= 4.1)]
    assert (twin.x_m.round(6).unique().tolist(), twin.y_m.round(6).unique().tolist()) == (
        [-0.2],
        [1.36],
    )  # held at its last pose in the world
    summary = (out / "summary.json").read_text()
    assert '"mocap_rejected_off_map": 19' in summary  # k = 41 .. 59

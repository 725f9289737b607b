"""``mocap.source = "bag"``: a recorded trajectory replayed as motion capture.

Each tracked robot follows a pose track of ``mocap.file`` (a ROS 2 bag's pose topic, or a
CSV: :mod:`adapters.bags.tracks`), replayed at its own stamps, shifted so that the first
pose of all falls at time 0; the replayed robot is a twin that follows it.
"""

from __future__ import annotations

from collections.abc import Generator, Iterator, Mapping
from pathlib import Path
from typing import Any, ClassVar

import simpy

from adapters.bags.tracks import PoseTrack, read_pose_track
from adapters.mocap.contract import SourceContext, Tracked
from adapters.mocap.settings import MocapConfig
from cosim.core.adapter import RunContext
from cosim.core.kernel import Stage
from cosim.scenario.fields import Problem


class RecordedSource:
    """Poses of a ROS 2 bag or a CSV file, at their own stamps (see the module)."""

    name: ClassVar[str] = "bag"
    external: ClassVar[bool] = True
    live: ClassVar[bool] = False
    uses_dds: ClassVar[bool] = False
    keys: ClassVar[tuple[str, ...]] = ("file", "bodies")

    @classmethod
    def problems(cls, mocap: MocapConfig) -> Iterator[Problem]:
        """A file to replay, and one body for a CSV file (it holds one track)."""
        if not mocap.file:
            yield Problem("file", mocap.file, "a bag or CSV file for source = 'bag'")
        if len(mocap.bodies) > 1 and mocap.file.endswith(".csv"):
            yield Problem("bodies", [list(b) for b in mocap.bodies], "one body for a CSV file")

    @classmethod
    def tracks(cls, mocap: MocapConfig, outside: Mapping[str, str], names: list[str]) -> Tracked:
        """``mocap.bodies`` (pose topics of the bag), or the first robot on the bag's only one."""
        return [(r, b) for r, b in mocap.bodies] or [(names[0], "")]

    @classmethod
    def describe(cls, mocap: MocapConfig, body: str) -> str:
        """The file and the topic."""
        return f"the pose track {body or '(the only pose topic)'} of {mocap.file}"

    def __init__(self, context: SourceContext) -> None:
        self.intake = context.intake
        file = Path(context.mocap.file)
        self.recorded = [
            (index, read_pose_track(file, body or None)) for index, body in context.tracked
        ]

    def start(self, run: RunContext) -> None:
        """Replay every track from the earliest stamp of all."""
        t0 = min(int(track.t_ns[0]) for _, track in self.recorded)
        for index, track in self.recorded:
            run.kernel.process(self._replay(run, index, track, t0))

    def _replay(
        self, run: RunContext, index: int, track: PoseTrack, t0_ns: int
    ) -> Generator[simpy.Event, Any, None]:
        kernel = run.kernel
        times = (track.t_ns - t0_ns).tolist()
        xs, ys, yaws = track.x_m.tolist(), track.y_m.tolist(), track.yaw_rad.tolist()
        for k, t in enumerate(times):
            if t > kernel.now_ns:
                yield kernel.timeout(t - kernel.now_ns, Stage.SENSING)
            self.intake.submit(index, t, xs[k], ys[k], yaws[k], mirror=True)

    def close(self) -> None:
        """Nothing to disconnect."""

    def summary(self) -> Mapping[str, Any]:
        """Nothing of its own."""
        return {}

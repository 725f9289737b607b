"""The motion-capture adapter: poses of the tracked robots from ``mocap.source``.

* ``simulated``: a Vicon-like system on the ``mocap`` host samples the ground truth of the
  tracked robots at ``mocap.rate_hz`` (SENSING stage), adds Gaussian noise, drops bodies
  from frames with probability ``mocap.dropout`` and sends each frame ``mocap.latency_ms``
  after the instant it shows, stamped with that instant. The robots drive by their
  commands as usual; their software localizes by these poses.
* ``bag``: a recorded trajectory (ROS 2 bag or CSV) replayed at its own stamps, shifted so
  the first pose falls at time 0; the replayed robot is a twin that follows it.
* ``motioncapture`` / ``ros2`` / ``unity``: live poses (the ``motioncapture`` library,
  PoseStamped topics over DDS, or PoseStamped topics Unity scenes publish to ``cosim run
  --unity``, :mod:`adapters.mocap.unity`) taken in at ``mocap.rate_hz``; stamps are wall
  clock, mapped to kernel time by the real-time kernel (Unity's: when the run took them
  in); the tracked robots are twins. The run never waits for the system: a source that
  fails ends the run at once, and one that has sent no pose of some tracked robot
  ``mocap.connect_timeout_s`` after the start ends it then
  (:class:`~adapters.mocap.live.LiveSourceError`, one line naming the system, its host,
  the robot and what was listened for; an event ``no_pose`` or ``mocap_failed``).

Every pose goes through :class:`adapters.mocap.intake.PoseIntake` and is published on
``/<robot>/pose`` from the ``mocap`` host, so it crosses the network model to the robot.
"""

from __future__ import annotations

from collections.abc import Generator, Mapping
from pathlib import Path
from typing import Any, ClassVar

import numpy as np
import simpy

from adapters.mocap.intake import PoseIntake
from adapters.mocap.live import LiveSource, LiveSourceError, open_live_source
from adapters.mocap.settings import MocapConfig
from adapters.mocap.tables import MOCAP, MocapRecords
from adapters.mocap.tracking import external_bodies, simulated_robots
from adapters.mocap.tracks import PoseTrack, read_pose_track
from adapters.mocap.unity import advertise_unity_poses
from cosim.core.adapter import RunContext
from cosim.core.errors import ConfigError
from cosim.core.hosts import HostKind
from cosim.core.kernel import Stage
from cosim.core.rng import BlockDraws
from cosim.core.table import TableSpec
from cosim.core.timebase import ms_to_ns, period_ns, s_to_ns
from models.fleet.kinematics import FleetState
from models.mocap.sampling import MocapParams, measure

MOCAP_HOST = "mocap"


class MocapAdapter:
    """Publishes the tracked robots' measured poses (see the module docstring)."""

    name: ClassVar[str] = "mocap"
    requires: ClassVar[tuple[str, ...]] = ("fleet",)
    tables: ClassVar[tuple[TableSpec, ...]] = (MOCAP,)
    """The tables it writes (documented in the table reference)."""

    def __init__(self, run: RunContext) -> None:
        self.cfg = cfg = run.settings(MocapConfig)
        self.source = run.scenario.source
        if cfg.source == "none":
            raise ConfigError(
                f"{self.source}: [scenario] adapters names 'mocap': expected mocap.source "
                "other than 'none'"
            )
        self.fleet = run.service(FleetState)
        self.host = run.add_host(MOCAP_HOST, HostKind.MOCAP)
        self.intake = PoseIntake(run, self.host)
        self.records = MocapRecords.of(run)
        self.recorder = run.recorder
        self.period_ns = period_ns(cfg.rate_hz)
        self.live: LiveSource | None = None
        self._unheard: set[int] = set()
        """Tracked robots of a live source with no pose yet."""
        self._deadline_ns = 0
        self._live_summary: dict[str, Any] = {}
        self.tracks: list[tuple[int, PoseTrack]] = []
        if cfg.source == "simulated":
            by_name = self.intake.index
            self.tracked = [by_name[r] for r in simulated_robots(run.scenario, self.fleet.names)]
            streams = [run.rng.stream(f"mocap/{self.fleet.names[i]}") for i in self.tracked]
            self._normals = BlockDraws(streams, width=3)
            self._uniforms = BlockDraws(
                [run.rng.stream(f"mocap/dropout/{self.fleet.names[i]}") for i in self.tracked],
                width=1,
                kind="uniform",
            )
            self.params = MocapParams(
                rate_hz=cfg.rate_hz,
                latency_ms=cfg.latency_ms,
                noise_std_m=cfg.noise_std_m,
                noise_std_rad=cfg.noise_std_rad,
                dropout=cfg.dropout,
            )
        else:
            self.bodies = self._bodies(run)
            self.tracked = [index for index, _ in self.bodies]
            mirrors = self.intake.mirrors
            for index in self.tracked:
                mirrors.add(index)
            if cfg.source == "unity":
                advertise_unity_poses(run, self.bodies)
            if cfg.source == "bag":
                self.tracks = [
                    (index, read_pose_track(Path(cfg.file), body or None))
                    for index, body in self.bodies
                ]
        for index in self.tracked:
            self.intake.advertise(index)

    def _bodies(self, run: RunContext) -> list[tuple[int, str]]:
        """(robot index, body) pairs of an external source, defaults filled in."""
        index = self.intake.index
        return [(index[r], body) for r, body in external_bodies(run.scenario, self.fleet.names)]

    def start(self, run: RunContext) -> None:
        """Start sampling, the replay, or taking in live poses."""
        kernel = run.kernel
        if self.cfg.source == "simulated":
            kernel.every(self.period_ns, self._frame, stage=Stage.SENSING)
        elif self.cfg.source == "bag":
            t0 = min(int(track.t_ns[0]) for _, track in self.tracks)
            for index, track in self.tracks:
                kernel.process(self._replay(run, index, track, t0))
        else:
            self.live = open_live_source(run, self.cfg, self.bodies)
            self._unheard = set(self.tracked)
            self._deadline_ns = kernel.now_ns + s_to_ns(self.cfg.connect_timeout_s)
            kernel.every(self.period_ns, self._take_live, stage=Stage.SENSING)

    # -- simulated --------------------------------------------------------------------
    def _frame(self, now_ns: int) -> None:
        fleet = self.fleet
        idx = self.tracked
        truth = np.stack([fleet.x[idx], fleet.y[idx], fleet.yaw[idx]], axis=1)
        normals = np.asarray(self._normals.draw(), dtype=np.float64)
        uniforms = np.asarray(self._uniforms.draw()[:, 0], dtype=np.float64)
        m = measure(truth, normals, uniforms, self.params)
        self.records.count("dropouts", int((~m.seen).sum()))
        frame = [
            (idx[k], float(x), float(y), float(yaw))
            for k, ((x, y, yaw), seen) in enumerate(
                zip(m.poses.tolist(), m.seen.tolist(), strict=True)
            )
            if seen
        ]
        if not frame:
            return
        latency = ms_to_ns(self.cfg.latency_ms)
        if latency == 0:
            self._send(frame, now_ns)
        else:
            self.intake.run.kernel.at(
                now_ns + latency, lambda: self._send(frame, now_ns), stage=Stage.SENSING
            )

    def _send(self, frame: list[tuple[int, float, float, float]], stamp_ns: int) -> None:
        submit = self.intake.submit
        for index, x, y, yaw in frame:
            submit(index, stamp_ns, x, y, yaw, mirror=False)

    # -- replay -----------------------------------------------------------------------
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

    # -- live -------------------------------------------------------------------------
    def _take_live(self, now_ns: int) -> None:
        """Take in what arrived; end the run on a failed or (at first) silent source.

        Raises:
            LiveSourceError: the source failed, or a tracked robot has had no pose
                ``mocap.connect_timeout_s`` after the start.
        """
        live = self.live
        assert live is not None
        for index, stamp_ns, x, y, yaw in live.take(now_ns):
            self._unheard.discard(index)
            self.intake.submit(index, stamp_ns, x, y, yaw, mirror=True, now_ns=now_ns)
        failure = live.failure()
        if failure is not None:
            self.recorder.event(now_ns, MOCAP_HOST, "mocap_failed", failure)
            raise LiveSourceError(f"{failure}; {self._expected()}")
        if self._unheard and now_ns >= self._deadline_ns:
            index = min(self._unheard)
            text = live.silence(index)
            self.recorder.event(now_ns, self.fleet.names[index], "no_pose", text)
            raise LiveSourceError(f"{text}; {self._expected()}")

    def _expected(self) -> str:
        """What a live source needs, and the keys that say where it is."""
        cfg = self.cfg
        keys = {
            "motioncapture": "mocap.system, mocap.hostname and mocap.bodies",
            "unity": "mocap.bodies or mocap.topic_pattern, and cosim run --unity",
        }.get(cfg.source, "mocap.bodies or mocap.topic_pattern, and physical.dds_domain")
        return (
            f"expected a pose of every tracked robot within mocap.connect_timeout_s = "
            f"{cfg.connect_timeout_s:g} s (see {keys})"
        )

    def close(self) -> None:
        """Disconnect a live source (its counts are kept for the summary)."""
        if self.live is not None:
            self._live_summary = self.live.summary()
            self.live.close()
            self.live = None

    def finish(self, run: RunContext) -> Mapping[str, Any]:
        """``mocap_*`` counts (and the live source's)."""
        self.close()
        return {**self.records.summary(), **self._live_summary}

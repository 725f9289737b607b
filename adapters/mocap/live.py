"""Live pose sources: polled by the kernel, never waited for.

A live source (a motion-capture system, ROS 2 topics over DDS, Unity scenes) sends poses
on the wall clock. :class:`PolledSource` takes what arrived every ``1 / mocap.rate_hz``
(SENSING stage) and hands it to the pose intake; no callback runs on another thread's
time. Its stamps are wall clock, mapped to kernel time by the real-time kernel. Nothing
received is trusted: samples that are not a pose are counted and dropped by the source,
the rest go through the intake's checks.

Nothing waits for the system: each poll asks whether the source failed
(:meth:`PolledSource.failure`) and, once ``mocap.connect_timeout_s`` has passed without
a pose of some tracked robot, ends the run with :class:`LiveSourceError` saying what the
source got that far (:meth:`PolledSource.silence`) and which keys say where it is
(:attr:`PolledSource.settings_hint`). A run that ends before the timeout was reached
(``scenario.duration_s`` shorter than it) fails the same way at its last poll when some
tracked robot has had no pose: a run that asked for live poses and got none is a mistake,
never a success with an empty table. ``mocap_connected`` in the summary says whether any
pose came from the source.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, ClassVar

from adapters.mocap.contract import SourceContext
from cosim.core.adapter import RunContext
from cosim.core.errors import BridgeError
from cosim.core.kernel import Stage
from cosim.core.summary import SummaryKey
from cosim.core.timebase import NS_PER_S, period_ns, s_to_ns
from cosim.scenario.sections import ScenarioSection
from models.fleet.kinematics import FleetState

Sample = tuple[int, int, float, float, float]
"""(robot index, stamp in kernel ns, x_m, y_m, yaw_rad) in ``map``."""


class LiveSourceError(BridgeError):
    """A live pose source failed, or sent no pose of a tracked robot in time."""


LIVE_SUMMARY: Mapping[str, SummaryKey] = {
    "mocap_connected": SummaryKey(
        "true/false", "whether any pose of a tracked robot came from the live system"
    ),
}
"""The summary key every live source writes (its subclasses' ``summary_keys`` hold it)."""


class PolledSource:
    """The polling of a live source; subclasses say what arrived and what went wrong.

    Subclasses implement :meth:`connect`, :meth:`take`, :meth:`silence`,
    :meth:`disconnect` and :meth:`counts` (and :meth:`failure` where the system can fail),
    and set :attr:`settings_hint`. Their counts are taken when the source closes.

    Args:
        context: the run, the ``[mocap]`` section, the intake and the tracked bodies.
    """

    external: ClassVar[bool] = True
    live: ClassVar[bool] = True
    settings_hint: ClassVar[str] = "mocap.bodies"
    """The keys (and flags) that say where the source is, for the timeout's message."""

    def __init__(self, context: SourceContext) -> None:
        self.context = context
        self.cfg = context.mocap
        self.names = list(context.run.service(FleetState).names)
        self.tracked = [index for index, _ in context.tracked]
        self._unheard: set[int] = set()
        self._start_ns = 0
        self._deadline_ns = 0
        self._end_ns = s_to_ns(context.run.settings(ScenarioSection).duration_s)
        self._period_ns = period_ns(self.cfg.rate_hz)
        self._connected = False
        self._summary: dict[str, Any] = {}

    def connect(self, run: RunContext) -> None:
        """Connect to the system (called when the run starts; must not block)."""

    def disconnect(self) -> None:
        """Disconnect from the system."""

    def counts(self) -> Mapping[str, Any]:
        """``mocap_*`` counts of the source for the run's summary."""
        return {}

    def close(self) -> None:
        """Take the counts and disconnect, once (nothing if it never connected)."""
        if self._connected:
            self._connected = False
            heard = len(self._unheard) < len(self.tracked)
            self._summary = {"mocap_connected": heard, **self.counts()}
            self.disconnect()

    @property
    def waited_s(self) -> float:
        """How long the source is waited for (s), for :meth:`silence`.

        ``mocap.connect_timeout_s``, or the whole run when it ends sooner.
        """
        return min(self.cfg.connect_timeout_s, (self._end_ns - self._start_ns) / NS_PER_S)

    def summary(self) -> Mapping[str, Any]:
        """The counts taken when the source closed (none before)."""
        return self._summary

    def take(self, now_ns: int) -> list[Sample]:
        """The poses that arrived since the last call, oldest first."""
        raise NotImplementedError

    def failure(self) -> str | None:
        """Why the source delivers nothing more (one line), or None while it may."""
        return None

    def silence(self, index: int) -> str:
        """What was listened to for robot ``index``, and what came (for an error line)."""
        raise NotImplementedError

    def start(self, run: RunContext) -> None:
        """Connect, then poll every ``1 / mocap.rate_hz`` until the run ends."""
        self.connect(run)
        self._connected = True
        self.recorder = run.recorder
        self._unheard = set(self.tracked)
        self._start_ns = run.kernel.now_ns
        self._deadline_ns = self._start_ns + s_to_ns(self.cfg.connect_timeout_s)
        run.kernel.every(self._period_ns, self._poll, stage=Stage.SENSING)

    def _poll(self, now_ns: int) -> None:
        """Take in what arrived; end the run on a failed or (at first) silent source.

        Raises:
            LiveSourceError: the source failed, or a tracked robot has had no pose
                ``mocap.connect_timeout_s`` after the start, or at the run's last poll
                when the run ends sooner.
        """
        submit = self.context.intake.submit
        for index, stamp_ns, x, y, yaw in self.take(now_ns):
            self._unheard.discard(index)
            submit(index, stamp_ns, x, y, yaw, mirror=True, now_ns=now_ns)
        failure = self.failure()
        host = self.context.host
        if failure is not None:
            self.recorder.event(now_ns, host, "mocap_failed", failure)
            raise LiveSourceError(f"{failure}; {self._expected()}")
        if not self._unheard:
            return
        last_poll = now_ns + self._period_ns >= self._end_ns
        if now_ns >= self._deadline_ns or last_poll:
            index = min(self._unheard)
            text = self.silence(index)
            self.recorder.event(now_ns, self.names[index], "no_pose", text)
            if now_ns >= self._deadline_ns:
                raise LiveSourceError(f"{text}; {self._expected()}")
            raise LiveSourceError(
                f"{text}; the run ended at {self._end_ns / NS_PER_S:g} s, within "
                f"mocap.connect_timeout_s = {self.cfg.connect_timeout_s:g} s: expected a pose "
                f"of every tracked robot before the run ends (see {self.settings_hint})"
            )

    def _expected(self) -> str:
        """What a live source needs, and the keys that say where it is."""
        return (
            f"expected a pose of every tracked robot within mocap.connect_timeout_s = "
            f"{self.cfg.connect_timeout_s:g} s (see {self.settings_hint})"
        )

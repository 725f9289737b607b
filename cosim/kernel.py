"""The event kernel: a SimPy environment in integer nanoseconds.

There is no second event loop: time moves only through SimPy events. The kernel adds
three things to a plain :class:`simpy.Environment`:

* **Stages.** Events due at the same instant run in stage order (:class:`Stage`), then in
  the order they were scheduled. Physics integrates before messages are delivered,
  sensors sample the integrated state, controllers act on fresh sensor data, and
  recorders sample last. SimPy's own events (``env.timeout``, process start) keep their
  priorities (0 and 1) and so run before every stage at the same instant.
* **Periodic callbacks** that reschedule themselves without a generator frame, so that
  thousands of exact-rate tasks stay cheap.
* **A counting run loop** that reports progress and the number of processed events.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Generator
from dataclasses import dataclass
from enum import IntEnum
from typing import Any

import simpy
import simpy.rt
from simpy.events import EventPriority


class Stage(IntEnum):
    """Order of events that fall on the same nanosecond (lower runs first)."""

    PHYSICS = 2
    """Kinematics integration and ground-truth contact checks."""
    DELIVERY = 3
    """Bus messages arriving over a link."""
    SENSING = 4
    """Sensors sampling the ground truth (lidar, motion capture, odometry)."""
    CONTROL = 5
    """Robot software: controllers, planners, protocols."""
    RECORD = 6
    """Samplers that write ground truth into the tables."""


class StagedTimeout(simpy.Event):
    """A timeout that fires in a given :class:`Stage` (SimPy's ``Timeout`` is fixed at NORMAL)."""

    def __init__(self, env: simpy.Environment, delay_ns: int, stage: Stage, value: Any = None):
        if delay_ns < 0:
            raise ValueError(f"negative delay {delay_ns} ns")
        super().__init__(env)
        self._ok = True
        self._value = value
        env.schedule(self, EventPriority(int(stage)), delay_ns)


@dataclass
class Periodic:
    """Handle of a periodic callback; :meth:`cancel` stops it before its next firing."""

    period_ns: int
    active: bool = True

    def cancel(self) -> None:
        """Stop the callback; a firing already scheduled is skipped."""
        self.active = False


ProgressFn = Callable[[int, int], None]
"""Called during :meth:`Kernel.run` with (sim time in ns, events processed so far)."""


class Kernel:
    """SimPy environment with integer-nanosecond time, stages and periodic callbacks.

    Args:
        realtime: pace the run against the wall clock (``simpy.rt.RealtimeEnvironment``,
            non-strict; lateness is the caller's to measure and report).
        speed: simulated seconds per wall-clock second when ``realtime`` (1.0: real time).
    """

    def __init__(self, *, realtime: bool = False, speed: float = 1.0) -> None:
        self.env: simpy.Environment
        if not speed > 0:
            raise ValueError(f"real-time speed must be > 0, got {speed}")
        if realtime:
            self.env = simpy.rt.RealtimeEnvironment(
                initial_time=0, factor=1e-9 / speed, strict=False
            )
        else:
            self.env = simpy.Environment(initial_time=0)
        self.events_processed = 0

    @property
    def now_ns(self) -> int:
        """Current simulation time in nanoseconds."""
        return int(self.env.now)

    def timeout(
        self, delay_ns: int, stage: Stage = Stage.CONTROL, value: Any = None
    ) -> simpy.Event:
        """Return an event that fires ``delay_ns`` from now in ``stage``."""
        return StagedTimeout(self.env, delay_ns, stage, value)

    def process(self, generator: Generator[simpy.Event, Any, Any]) -> simpy.Process:
        """Start a SimPy process."""
        return self.env.process(generator)

    def at(self, t_ns: int, fn: Callable[[], None], stage: Stage = Stage.CONTROL) -> None:
        """Call ``fn()`` once at absolute time ``t_ns`` (not in the past)."""
        event = StagedTimeout(self.env, t_ns - self.now_ns, stage)
        event.callbacks.append(lambda _event: fn())

    def every(
        self,
        period_ns: int,
        fn: Callable[[int], None],
        *,
        stage: Stage,
        start_ns: int | None = None,
    ) -> Periodic:
        """Call ``fn(now_ns)`` at ``start_ns + k * period_ns`` for k = 0, 1, 2, ...

        Firing times are exact multiples of the period: the next firing is scheduled from
        the nominal time, never from a measured one.

        Args:
            period_ns: period in nanoseconds, > 0.
            fn: callback receiving the current time in ns.
            stage: the stage the callback runs in.
            start_ns: first firing (absolute ns); defaults to now.
        """
        if period_ns <= 0:
            raise ValueError(f"period must be positive, got {period_ns} ns")
        handle = Periodic(period_ns)
        env = self.env
        first = self.now_ns if start_ns is None else start_ns
        if first < self.now_ns:
            raise ValueError(f"start {first} ns is in the past (now {self.now_ns} ns)")
        priority = EventPriority(int(stage))

        def fire(event: simpy.Event) -> None:
            if not handle.active:
                return
            fn(int(env.now))
            nxt = simpy.Event(env)
            nxt._ok = True
            nxt._value = None
            nxt.callbacks.append(fire)
            env.schedule(nxt, priority, period_ns)

        StagedTimeout(env, first - self.now_ns, stage).callbacks.append(fire)
        return handle

    def run(
        self,
        until_ns: int,
        *,
        progress: ProgressFn | None = None,
        progress_interval_s: float = 0.5,
    ) -> int:
        """Process every event due strictly before ``until_ns``; return how many ran.

        Events due exactly at ``until_ns`` stay unprocessed (as with ``env.run(until)``)
        and ``now_ns`` ends at ``until_ns``. A failed event re-raises its exception.

        Args:
            until_ns: end of the run in ns.
            progress: called about every ``progress_interval_s`` of wall time.
            progress_interval_s: wall-clock seconds between progress calls.
        """
        env = self.env
        if isinstance(env, simpy.rt.RealtimeEnvironment) and self.events_processed == 0:
            env.sync()  # the wall clock starts with the run, not when the kernel was built
        step = env.step
        peek = env.peek
        processed = 0
        next_report = time.monotonic() + progress_interval_s
        while peek() < until_ns:
            step()
            processed += 1
            if progress is not None and processed & 0x3FF == 0:
                wall = time.monotonic()
                if wall >= next_report:
                    progress(self.now_ns, processed)
                    next_report = wall + progress_interval_s
        if until_ns > self.now_ns:
            env.run(until=until_ns)
        self.events_processed += processed
        if progress is not None:
            progress(self.now_ns, processed)
        return processed

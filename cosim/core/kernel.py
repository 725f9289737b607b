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
* **A counting run loop** that reports progress and the number of processed events, and
  lets the exception a failed process raised out as it was raised (:func:`escaped`).
"""

from __future__ import annotations

import time
from array import array
from collections.abc import Callable, Generator
from dataclasses import dataclass, field
from enum import IntEnum
from typing import Any

import simpy
import simpy.rt
from simpy.events import EventPriority

HEARTBEAT_EVENTS = 256
"""Events between two heartbeats (and looks at the wall clock for progress) of a run."""
_HEARTBEAT_MASK = HEARTBEAT_EVENTS - 1


def escaped(error: BaseException) -> BaseException:
    """The exception a failed process raised, where SimPy raised a copy of it (or failed to).

    SimPy crashes a run on a failed process by raising ``type(e)(*e.args)``, a copy with a
    new traceback through its own ``step``; a class whose constructor does not take its
    ``args`` back (``MyError(code, text)``) fails there with an error of its own. Either
    way, this returns the exception the process's code raised, with the frames it came
    through; any other exception as it is.
    """
    cause = error.__cause__
    if cause is not None and type(cause) is type(error) and cause.args == error.args:
        return cause
    trace = error.__traceback__
    while trace is not None:  # the copy's constructor failed: the event is in step's frame
        if trace.tb_frame.f_code is _STEP:
            event = trace.tb_frame.f_locals.get("event")
            value = getattr(event, "_value", None)
            if isinstance(value, BaseException) and not event._ok and value is not error:  # type: ignore[union-attr]
                return value
            break
        trace = trace.tb_next
    return error


_STEP = simpy.Environment.step.__code__


class Stage(IntEnum):
    """Order of events that fall on the same nanosecond (lower runs first)."""

    DECISION = 1
    """A learning agent's policy deciding on the instant as it stood before it (its actions
    go out in ``CONTROL``), as a learning environment observes between two kernel steps.
    It shares SimPy's ``NORMAL`` priority, which cosim's own events do not use."""
    PHYSICS = 2
    """Kinematics integration and ground-truth contact checks."""
    EXTERNAL = 3
    """What other simulators move (people and vehicles from SUMO), after the robots moved."""
    DELIVERY = 4
    """Bus messages arriving over a link."""
    SENSING = 5
    """Sensors sampling the ground truth (lidar, motion capture, odometry)."""
    CONTROL = 6
    """Robot software: controllers, planners, protocols."""
    RECORD = 7
    """Samplers that write ground truth into the tables."""
    LINK = 8
    """A network backend catching up with the instant's messages before time moves on (an
    external network simulator stepped event by event)."""


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


@dataclass
class Lateness:
    """How far a real-time run fell behind the wall clock, one entry per event batch.

    A batch is the events due at one simulated instant. Its lateness is measured when its
    first event is due to run: the wall-clock time past the instant the batch should have
    started (0 when the kernel was early and slept). Nothing is absorbed: a late batch is
    recorded late, and the run goes on from there (SimPy's non-strict real-time mode).

    Attributes:
        t_ns: the batches' simulated instants (ns).
        late_ns: their lateness in wall-clock ns (>= 0).
        events: events processed in each batch.
    """

    t_ns: array[int] = field(default_factory=lambda: array("q"))
    late_ns: array[int] = field(default_factory=lambda: array("q"))
    events: array[int] = field(default_factory=lambda: array("q"))

    def close_batch(self, batch_events: int) -> None:
        """Close the batch under way, the columns of one length however the run ended.

        A stop (Ctrl-C, an error) may land between the appends of a batch's columns.

        Args:
            batch_events: events processed in the batch under way.
        """
        if len(self.events) < len(self.t_ns):
            self.events.append(batch_events)
        rows = min(len(self.t_ns), len(self.late_ns), len(self.events))
        for column in (self.t_ns, self.late_ns, self.events):
            del column[rows:]


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
        """Events that completed in :meth:`run` (a failed or stopped run's included)."""
        self.speed = speed
        self.lateness: Lateness | None = Lateness() if realtime else None
        """Per-batch lateness of a real-time run (None when not real time)."""
        self._wall_epoch_ns = time.time_ns()
        self._after: list[Callable[[], None]] = []

    @property
    def realtime(self) -> bool:
        """Whether the kernel is paced against the wall clock."""
        return self.lateness is not None

    def wall_ns(self, t_ns: int) -> int:
        """The wall-clock time (ns since the Unix epoch) of simulated instant ``t_ns``.

        Only meaningful in real time (before the run starts it is the construction time);
        used to stamp what goes to real systems, which keep ROS time.
        """
        return self._wall_epoch_ns + round(t_ns / self.speed)

    def sim_ns(self, wall_ns: int) -> int:
        """The simulated instant of wall-clock time ``wall_ns`` (ns since the Unix epoch)."""
        return round((wall_ns - self._wall_epoch_ns) * self.speed)

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

    def after_event(self, fn: Callable[[], None]) -> None:
        """Call ``fn()`` once the event being processed is done, before any other event.

        What one event hands over piece by piece (a fleet's scans in one publication, every
        robot's map in one tick) can so be taken up as a whole at the same instant, as if
        each piece had been taken up on arrival: nothing else runs in between. Asked for
        outside :meth:`run` (before the run starts), it is called when :meth:`run` starts.
        """
        self._after.append(fn)

    def _flush_after(self) -> None:
        while self._after:
            due, self._after = self._after, []
            for fn in due:
                fn()

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
        heartbeat: Callable[[], None] | None = None,
    ) -> int:
        """Process every event due strictly before ``until_ns``; return how many ran.

        Events due exactly at ``until_ns`` stay unprocessed (as with ``env.run(until)``)
        and ``now_ns`` ends at ``until_ns``. A failed event re-raises its exception.

        Args:
            until_ns: end of the run in ns.
            progress: called about every ``progress_interval_s`` of wall time.
            progress_interval_s: wall-clock seconds between progress calls.
            heartbeat: called every :data:`HEARTBEAT_EVENTS` events (every event in real
                time): the run is alive (a watchdog's beat).
        """
        env = self.env
        self._flush_after()  # asked for before the run
        if isinstance(env, simpy.rt.RealtimeEnvironment):
            if self.events_processed == 0:
                # the wall clock starts with the run, not when the kernel was built
                env.sync()
                self._wall_epoch_ns = time.time_ns() - round(self.now_ns / self.speed)
            return self._run_realtime(env, until_ns, progress, progress_interval_s, heartbeat)
        step = env.step
        peek = env.peek
        processed = 0
        next_report = time.monotonic() + progress_interval_s
        checks = progress is not None or heartbeat is not None
        try:
            while peek() < until_ns:
                step()
                if self._after:
                    self._flush_after()
                processed += 1
                if checks and processed & _HEARTBEAT_MASK == 0:
                    if heartbeat is not None:
                        heartbeat()
                    wall = time.monotonic()
                    if progress is not None and wall >= next_report:
                        progress(self.now_ns, processed)
                        next_report = wall + progress_interval_s
        except BaseException as error:
            original = escaped(error)
            if original is error:
                raise
            raise original from original.__cause__
        finally:  # a failed event or a stop: the events that completed still count
            self.events_processed += processed
        if until_ns > self.now_ns:
            env.run(until=until_ns)
        if progress is not None:
            progress(self.now_ns, processed)
        return processed

    def advance(self, until_ns: int, woken: Callable[[], bool]) -> int:
        """Process events due before ``until_ns``, ending early after an instant that woke.

        After the last event of each instant, ``woken()`` is asked; if true, the kernel stops
        there (``now_ns`` is that instant, all of its events processed), else it goes on.
        Otherwise as :meth:`run` without progress: ``now_ns`` ends at ``until_ns``. A
        learning environment's event-driven decisions (:mod:`cosim.envs`) are made so.

        Args:
            until_ns: the latest end (ns).
            woken: whether something happened that the caller stops for.

        Returns:
            The number of events processed.
        """
        if self.realtime:
            raise ValueError("advance() steps a kernel that is not paced in real time")
        env = self.env
        self._flush_after()
        step, peek = env.step, env.peek
        processed = 0
        try:
            while peek() < until_ns:
                step()
                if self._after:
                    self._flush_after()
                processed += 1
                if peek() > env.now and woken():
                    return processed
        except BaseException as error:
            original = escaped(error)
            if original is error:
                raise
            raise original from original.__cause__
        finally:
            self.events_processed += processed
        if until_ns > self.now_ns:
            env.run(until=until_ns)
        return processed

    def _run_realtime(
        self,
        env: simpy.rt.RealtimeEnvironment,
        until_ns: int,
        progress: ProgressFn | None,
        progress_interval_s: float,
        heartbeat: Callable[[], None] | None = None,
    ) -> int:
        """The run loop of a real-time kernel: paced, and lateness measured per batch."""
        assert self.lateness is not None
        record = self.lateness
        peek = env.peek
        step = env.step
        monotonic = time.monotonic
        factor = env.factor
        processed = 0
        batch_t = -1
        batch_events = 0
        next_report = monotonic() + progress_interval_s
        try:
            while (t := peek()) < until_ns:
                if t != batch_t:
                    if batch_t >= 0:
                        record.events.append(batch_events)
                    due = env.real_start + (t - env.env_start) * factor
                    late_ns = max(0, round((monotonic() - due) * 1e9))
                    record.t_ns.append(int(t))
                    record.late_ns.append(late_ns)
                    batch_t, batch_events = int(t), 0
                step()
                if self._after:
                    self._flush_after()
                processed += 1
                batch_events += 1
                if heartbeat is not None:
                    heartbeat()
                if progress is not None and monotonic() >= next_report:
                    progress(self.now_ns, processed)
                    next_report = monotonic() + progress_interval_s
        except BaseException as error:
            original = escaped(error)
            if original is error:
                raise
            raise original from original.__cause__
        finally:  # a stop (Ctrl-C, an error) may land anywhere: keep the columns aligned
            record.close_batch(batch_events)
            self.events_processed += processed
        if until_ns > self.now_ns:
            env.run(until=until_ns)
        if progress is not None:
            progress(self.now_ns, processed)
        return processed

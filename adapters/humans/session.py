"""One running SUMO simulation: libsumo in this process, or SUMO in a child process.

libsumo runs a single simulation per process. The first session of a process takes it;
a session opened while another one runs (two runs on threads, a Dask worker with two
threads) starts the ``sumo`` program of the same eclipse-sumo release as a child process
and talks TraCI to it over loopback: the same program, the same results, only slower.

Every libsumo or TraCI error becomes a :class:`~cosim.core.errors.BridgeError` carrying
SUMO's own last error line (SUMO writes its errors into ``sumo.log`` beside the files),
so nothing SUMO-specific crosses a process boundary.
"""

from __future__ import annotations

import contextlib
import io
import math
import subprocess
import threading
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import libsumo
import numpy as np
import numpy.typing as npt
import traci
from traci import constants as tc

from adapters.humans.files import sumo_tool
from cosim.core.errors import BridgeError
from models.arrays import FloatArray
from models.geometry.angles import wrap_angles

SUMO_ERRORS: tuple[type[BaseException], ...] = (
    libsumo.TraCIException,
    libsumo.FatalTraCIError,
    traci.TraCIException,
    traci.FatalTraCIError,
)
"""What libsumo and TraCI raise."""
STAGE_WAITING = 1
"""TraCI's stage type of a person staying somewhere."""
PERSON_VARS = (
    tc.VAR_POSITION,
    tc.VAR_ANGLE,
    tc.VAR_SPEED,
    tc.VAR_ROAD_ID,
    tc.VAR_LANEPOSITION,
    tc.VAR_STAGES_REMAINING,
)
VEHICLE_VARS = (tc.VAR_POSITION, tc.VAR_ANGLE, tc.VAR_SPEED)

MATCH_THRESHOLD_M = 4.0
"""How far from a robot SUMO first looks for a lane to put its mirror on (m): the search
costs in proportion (SUMO's default, 100 m, is the fallback)."""

PACE_STEP_MPS = 0.02
"""Smallest change of a walker's speed limit passed on to SUMO (m/s)."""

_LIBSUMO = threading.Lock()
"""Held by the session that runs in this process through libsumo."""
_LABELS = iter(range(1 << 62))


@dataclass(frozen=True)
class Movers:
    """Where SUMO's people and vehicles are after a step (frame ``map``).

    Attributes:
        names: their SUMO ids.
        x_m, y_m: positions (m): a person's position, a vehicle's front centre.
        yaw_rad: headings (rad, counter-clockwise from +x).
        speed_mps: speeds (m/s).
        staying: for people, who stays somewhere (a pick station, the dock) rather than
            walks; ``None`` for vehicles.
    """

    names: list[str]
    x_m: FloatArray
    y_m: FloatArray
    yaw_rad: FloatArray
    speed_mps: FloatArray
    staying: npt.NDArray[np.bool_] | None = None


def yaw_of_angle(angle_deg: FloatArray) -> FloatArray:
    """SUMO's heading (deg, clockwise from north) as yaw (rad, counter-clockwise from +x)."""
    return wrap_angles(np.radians(90.0 - np.asarray(angle_deg)))


def angle_of_yaw(yaw_rad: float) -> float:
    """Yaw (rad) as SUMO's heading (deg, clockwise from north, in [0, 360))."""
    return (90.0 - math.degrees(yaw_rad)) % 360.0


class SumoSession:
    """A SUMO simulation loaded from a ``.sumocfg`` and stepped from outside."""

    def __init__(self, config: Path, *, seed: int) -> None:
        """Load ``config``.

        Args:
            config: the ``.sumocfg`` (network and demand beside it).
            seed: SUMO's random seed.

        Raises:
            BridgeError: if SUMO refuses the files (its error line is in the message).
        """
        self.log = config.with_name("sumo.log")
        self.log.unlink(missing_ok=True)
        command = [
            str(sumo_tool("sumo")),
            "-c", str(config),
            "--seed", str(seed),
            "--log", str(self.log),
            "--no-warnings", "true",
            "--no-step-log", "true",
            "--duration-log.disable", "true",
        ]  # fmt: skip
        self.in_process = _LIBSUMO.acquire(blocking=False)
        self._api: Any = libsumo
        self._closed = False
        try:
            with self.errors("load"):
                if self.in_process:
                    libsumo.start(command)
                else:
                    label = f"cosim-{next(_LABELS)}"
                    with contextlib.redirect_stdout(io.StringIO()):  # "Retrying in 1 seconds"
                        traci.start(command, label=label, stdout=subprocess.DEVNULL)
                    self._api = traci.getConnection(label)
        except BaseException:
            if self.in_process:
                _LIBSUMO.release()
            self._closed = True
            raise
        self._people: set[str] = set()
        self._vehicles: set[str] = set()
        self._waiting: dict[tuple[str, float], tuple[float, float]] = {}
        self._robots: list[str] = []
        self._remaining: dict[str, int] = {}
        self._own_speed: dict[str, tuple[float, float]] = {}
        self._paced: dict[str, float] = {}
        self._top_speed: dict[str, float] = {}
        self._paced_vehicles: dict[str, float] = {}
        self.arrivals = 0
        """Walks that ended at a place where the person stays (a pick station, the dock)."""

    @contextlib.contextmanager
    def errors(self, doing: str) -> Iterator[None]:
        """Turn SUMO's exceptions inside the block into a BridgeError."""
        try:
            yield
        except SUMO_ERRORS as error:
            raise BridgeError(f"SUMO failed to {doing}: {self._reason(error)}") from None

    def _reason(self, error: BaseException) -> str:
        lines: list[str] = []
        if self.log.is_file():
            text = self.log.read_text(encoding="utf-8", errors="replace")
            lines = [line for line in text.splitlines() if line.startswith("Error")]
        if lines:
            return f"{lines[-1]} (SUMO's log: {self.log})"
        message = getattr(error, "getString", None)
        text = str(message() if callable(message) else error)
        return " ".join(text.split())

    @property
    def time_s(self) -> float:
        """SUMO's current time (s)."""
        with self.errors("read the time"):
            return float(self._api.simulation.getTime())

    def add_robots(self, names: Sequence[str], edge: str) -> None:
        """Mirror the robots into SUMO as vehicles that people walk around."""
        with self.errors("add the robots"):
            self._api.route.add("cosim_robot", [edge])
            for name in names:
                self._api.vehicle.add(name, "cosim_robot", typeID="robot", depart="now")
                self._api.vehicle.setSpeedMode(name, 0)
        self._robots = list(names)

    def move_robots(self, x_m: FloatArray, y_m: FloatArray, yaw_rad: FloatArray) -> None:
        """Place the robots' mirrors at their poses (``map``) before the next step."""
        # every step, also a robot at rest: a mirror left alone drives on along the lane it
        # was put on and leaves SUMO at the lane's end
        move = self._api.vehicle.moveToXY
        with self.errors("move the robots"):
            for name, x, y, yaw in zip(
                self._robots, x_m.tolist(), y_m.tolist(), yaw_rad.tolist(), strict=True
            ):
                angle = angle_of_yaw(yaw)
                try:
                    move(name, "", -1, x, y, angle, 2, MATCH_THRESHOLD_M)
                except SUMO_ERRORS:  # no lane that close: look as far as SUMO does
                    move(name, "", -1, x, y, angle, 2)

    def pace(self, names: Sequence[str], speed_mps: FloatArray) -> None:
        """Let these walkers walk at most this fast (m/s) from the next step on.

        A walker's own speed (their type's) and speed factor (SUMO's individual deviation)
        are kept the first time they are paced; a limit at or above it gives it back, one below
        ``PACE_STEP_MPS`` stops them. SUMO is asked only when a walker's limit changes by
        more than ``PACE_STEP_MPS`` or reaches 0 or their own speed.
        """
        person = self._api.person
        with self.errors("set a person's speed"):
            for name, limit in zip(names, speed_mps.tolist(), strict=True):
                found = self._own_speed.get(name)
                if found is None:
                    found = (float(person.getMaxSpeed(name)), float(person.getSpeedFactor(name)))
                    self._own_speed[name] = found
                own, factor = found
                # SUMO walks a person at the speed set times their own speed factor; below
                # the step a walker stands: a small limit left in place would let them creep
                limit = min(limit / factor, own) if limit >= PACE_STEP_MPS else 0.0
                last = self._paced.get(name, own)
                if abs(limit - last) > PACE_STEP_MPS or (limit != last and limit in (0.0, own)):
                    person.setSpeed(name, limit)
                    self._paced[name] = limit

    def pace_vehicles(self, names: Sequence[str], speed_mps: FloatArray) -> None:
        """Let these forklifts drive at most this fast (m/s) from the next step on.

        A limit at or above a forklift's own top speed (or ``inf``) hands its speed back to
        SUMO's car-following; a lower one is set with ``vehicle.setSpeed`` (SUMO brakes
        within the type's ``decel``), one below ``PACE_STEP_MPS`` stops it. SUMO is asked
        only when a limit changes by more than ``PACE_STEP_MPS``, stops or frees it.
        """
        vehicle = self._api.vehicle
        with self.errors("set a forklift's speed"):
            for name, limit in zip(names, speed_mps.tolist(), strict=True):
                top = self._top_speed.get(name)
                if top is None:
                    top = self._top_speed[name] = float(vehicle.getMaxSpeed(name))
                target = -1.0 if limit >= top else (limit if limit >= PACE_STEP_MPS else 0.0)
                last = self._paced_vehicles.get(name, -1.0)
                changed = abs(target - last) > PACE_STEP_MPS
                if changed or (target != last and (target == 0.0 or -1.0 in (target, last))):
                    vehicle.setSpeed(name, target)
                    self._paced_vehicles[name] = target

    def step(self, until_s: float) -> None:
        """Advance SUMO to ``until_s`` (s) and subscribe to whoever appeared."""
        api = self._api
        with self.errors(f"step to {until_s:g} s"):
            api.simulationStep(until_s)
            for name in api.simulation.getDepartedPersonIDList():
                api.person.subscribe(name, PERSON_VARS)
            for name in api.simulation.getDepartedIDList():
                if name not in self._robots:
                    api.vehicle.subscribe(name, VEHICLE_VARS)

    def people(self) -> Movers:
        """The people walking or standing now, sorted by id."""
        api = self._api
        with self.errors("read the people"):
            found = api.person.getAllSubscriptionResults()
            names = sorted(found)
            x = np.empty(len(names))
            y = np.empty(len(names))
            angle = np.empty(len(names))
            speed = np.empty(len(names))
            staying = np.zeros(len(names), dtype=bool)
            for k, name in enumerate(names):
                values = found[name]
                (x[k], y[k]), angle[k], speed[k] = (
                    values[tc.VAR_POSITION],
                    values[tc.VAR_ANGLE],
                    values[tc.VAR_SPEED],
                )
                remaining = int(values[tc.VAR_STAGES_REMAINING])
                ended = remaining < self._remaining.get(name, remaining)
                self._remaining[name] = remaining
                if (speed[k] == 0.0 or ended) and api.person.getStage(name).type == STAGE_WAITING:
                    # SUMO draws a person who stays somewhere 3 m beside the lane; they
                    # stand on it
                    x[k], y[k] = self._on_lane(values[tc.VAR_ROAD_ID], values[tc.VAR_LANEPOSITION])
                    self.arrivals += ended
                    staying[k] = True
        return Movers(names, x, y, yaw_of_angle(angle), speed, staying)

    def _on_lane(self, edge: str, position: float) -> tuple[float, float]:
        key = (edge, position)
        found = self._waiting.get(key)
        if found is None:
            x, y = self._api.simulation.convert2D(edge, position, 0)
            found = self._waiting[key] = (float(x), float(y))
        return found

    def vehicles(self) -> Movers:
        """The forklifts driving or stopped now (not the robots' mirrors), sorted by id."""
        with self.errors("read the vehicles"):
            found = self._api.vehicle.getAllSubscriptionResults()
        names = sorted(name for name in found if name not in self._robots)
        values = [found[name] for name in names]
        xy = np.array([v[tc.VAR_POSITION] for v in values], dtype=float).reshape(-1, 2)
        angle = np.array([v[tc.VAR_ANGLE] for v in values], dtype=float)
        speed = np.array([v[tc.VAR_SPEED] for v in values], dtype=float)
        return Movers(names, xy[:, 0], xy[:, 1], yaw_of_angle(angle), speed)

    def close(self) -> None:
        """End the simulation (and its process); the session cannot be used after."""
        if self._closed:
            return
        self._closed = True
        try:
            if self.in_process:
                libsumo.close()
            else:
                self._api.close()
        except SUMO_ERRORS:
            pass  # closing a simulation that failed: nothing left to free
        finally:
            if self.in_process:
                _LIBSUMO.release()

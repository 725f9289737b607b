"""The humans adapter: workers and forklifts from SUMO, stepped in lockstep with the kernel.

At construction it builds the aisle graph of the warehouse, draws the demand from the
``humans/demand`` stream, writes SUMO's files (network through netconvert, demand,
config) and keeps them for the run folder's ``sumo/``.

**Synchronization.** Every ``humans.step_length_s`` (Δ) at instant t_k = kΔ, in the
``EXTERNAL`` stage (after the robots' physics step of that instant, before any sensor):

1. the robots' mirrors in SUMO are placed at the robots' true poses at t_k;
2. SUMO advances from t_(k-1) to t_k (its clock equals the kernel's after every step;
   people appear from t_1 = Δ on), its people reacting to the mirrors as placed;
3. a person SUMO put reaching into a shelf (its lane runs along the shelf's face) is
   moved out until it touches it (``humans_pushed_out`` counts these samples); with
   ``humans.avoid_robots``, a walker's step from their last published position is cut
   where it would come within a margin of a robot (``humans_steps_cut``, rare);
4. people and forklifts at t_k become the run's dynamic obstacles, seen by every lidar
   and collision check until t_(k+1) (sample and hold);
5. with ``humans.avoid_robots``, each walker's speed for SUMO's next step is set by the
   collision-free speed model (:mod:`models.humans.avoidance`, Tordeux et al. 2016):
   slower as a robot's footprint comes nearer ahead, 0 (waiting, ``humans_yields``
   counts these) when it is within the margin. SUMO keeps routing; its own pedestrians
   only give way to a vehicle ahead on their lane.

There is no lookahead: SUMO never runs ahead of the kernel. People react to robots with
a delay of up to one step; between steps cosim holds a person where SUMO put them at
t_k, so the true position differs from the held one by at most v·Δ (0.12 m for a worker
at 1.2 m/s and Δ = 0.1 s, 0.22 m for a forklift at 2.2 m/s). Lidar ranges and
clearances to people carry that error.
"""

from __future__ import annotations

import shutil
import tempfile
import time
import weakref
from collections.abc import Mapping
from dataclasses import replace
from pathlib import Path
from typing import Any, ClassVar, Literal

import numpy as np

from adapters.humans.crowd import People
from adapters.humans.files import (
    TrafficTypes,
    write_config,
    write_demand,
    write_network,
)
from adapters.humans.session import Movers, SumoSession
from adapters.humans.settings import HumansConfig
from adapters.humans.tables import HUMANS, HUMANS_SUMMARY, HumanRecords
from cosim.core.adapter import RunContext
from cosim.core.kernel import Stage
from cosim.core.summary import SummaryKey
from cosim.core.table import TableSpec
from cosim.core.timebase import NS_PER_S, period_ns
from cosim.scenario.fields import model_problem
from cosim.scenario.sections import RobotsConfig, ScenarioSection
from models.arrays import FloatArray
from models.errors import ModelError
from models.fleet.kinematics import FleetState
from models.humans.aisles import AisleGraph, IntArray, aisle_graph, dock_points, pick_stations
from models.humans.avoidance import free_distance, room, safe_step, speed_limit, step_aside
from models.humans.bodies import push_out, two_disc_cover, vehicle_centres
from models.humans.demand import Plan, plans, standing_plans
from models.world.obstacles import DynamicObstacles
from models.world.warehouse import Warehouse

WAIT_MPS = 0.05
"""A walker the speed model limits below this is waiting for a robot (m/s)."""
CLEARANCE_MARGIN_M = 0.1
"""Aisle lines keep a worker's radius plus this from shelves and walls (m)."""


class HumansAdapter:
    """People and forklifts in the aisles, co-simulated with SUMO through libsumo."""

    name: ClassVar[str] = "humans"
    requires: ClassVar[tuple[str, ...]] = ("world", "fleet")
    tables: ClassVar[tuple[TableSpec, ...]] = (HUMANS,)
    """The tables it writes (documented in the table reference)."""
    summary_keys: ClassVar[Mapping[str, SummaryKey]] = {
        **HUMANS_SUMMARY,
        "humans_workers": SummaryKey("count", "walking workers (humans.workers)"),
        "humans_standing": SummaryKey("count", "standing workers (humans.standing)"),
        "humans_forklifts": SummaryKey("count", "forklifts (humans.forklifts)"),
        "humans_sumo_steps": SummaryKey("count", "SUMO steps taken"),
        "humans_pushed_out": SummaryKey(
            "count", "person samples SUMO put reaching into a shelf or wall, moved out"
        ),
        "humans_yields": SummaryKey("count", "times a walker stopped to let a robot pass"),
        "humans_steps_cut": SummaryKey(
            "count", "walker steps cut short of a robot (SUMO's step would have touched it)"
        ),
        "humans_forklift_yields": SummaryKey(
            "count", "times a forklift stopped to let a robot pass"
        ),
        "humans_trips": SummaryKey("count", "walks SUMO completed"),
        "humans_coupling_wall_s": SummaryKey(
            "s", "wall-clock time spent stepping SUMO and exchanging positions", volatile=True
        ),
        "humans_sumo_in_process": SummaryKey(
            "true/false",
            "SUMO ran inside the process (libsumo) rather than as a TraCI server",
            volatile=True,
        ),
    }
    """The summary keys :meth:`finish` writes (documented in the summary reference)."""

    def __init__(self, run: RunContext) -> None:
        cfg = run.settings(HumansConfig)
        self.cfg = cfg
        world = run.service(Warehouse)
        self.fleet = run.service(FleetState)
        self.dynamic = run.service(DynamicObstacles)
        self.graph, stations, docks = _graph(run, world)
        demand = _demand(run, self.graph, stations, docks)
        limits = run.settings(RobotsConfig)
        duration_s = run.settings(ScenarioSection).duration_s
        self.folder = Path(tempfile.mkdtemp(prefix="cosim-sumo-"))
        # removed by close(); also when a run is assembled but never started (cosim check)
        weakref.finalize(self, shutil.rmtree, self.folder, True)
        self.step_ns = period_ns(1.0 / cfg.step_length_s)
        self.seed = int(run.rng.stream("humans/sumo").integers(1, 2**31 - 1))
        try:
            lanes = write_network(
                self.graph,
                self.folder,
                forklifts=cfg.forklifts > 0,
                inset_m=2 * cfg.worker_radius_m,
            )
            types = TrafficTypes(
                worker_width_m=2 * cfg.worker_radius_m,
                worker_speed_mps=cfg.worker_speed_mps,
                robot_size_m=2 * limits.radius_m,
                robot_speed_mps=limits.max_speed_mps,
                forklift_length_m=cfg.forklift_size_m[0],
                forklift_width_m=cfg.forklift_size_m[1],
                forklift_speed_mps=cfg.forklift_speed_mps,
            )
            write_demand(self.graph, demand, lanes, types, self.folder)
            self.config = write_config(
                self.folder,
                step_s=self.step_ns / NS_PER_S,
                seed=self.seed,
                end_s=duration_s + 1.0,
                # a stripe per person's width: two people pass each other in a 1.1 m lane
                stripe_width_m=2 * cfg.worker_radius_m,
                jam_time_s=cfg.jam_time_s,
            )
        except BaseException:
            shutil.rmtree(self.folder, ignore_errors=True)
            raise
        self.people = People()
        self.people.forklift_size_m = cfg.forklift_size_m
        self.people.worker_radius_m = cfg.worker_radius_m
        run.provide(self.people)
        self.records = HumanRecords(run, cfg)
        self.recorder = run.recorder
        self.session: SumoSession | None = None
        self.steps = 0
        self.coupling_s = 0.0
        self.boxes = world.boxes
        self.last_xy: dict[str, tuple[float, float]] = {}
        """Every walker's last published position (m, ``map``)."""
        self.cut = 0
        """Walker steps cut short of a robot (see ``_keep_clear``)."""
        self.yields = 0
        self.waiting: set[str] = set()
        self.forklift_yields = 0
        self.forklifts_waiting: set[str] = set()
        """Walkers the speed model holds still for a robot now."""
        self.pushed = 0
        """Person samples SUMO put reaching into a shelf or wall, moved out (see push_out)."""

    def start(self, run: RunContext) -> None:
        """Start SUMO, mirror the robots into it and step it every ``step_length_s``."""
        self.session = SumoSession(self.config, seed=self.seed)
        self.session.add_robots(self.fleet.names, "e0")
        # SUMO starts at 0 with nobody inserted yet; its first step brings it to Δ
        run.kernel.every(
            self.step_ns,
            lambda now: self._step(run, now),
            stage=Stage.EXTERNAL,
            start_ns=self.step_ns,
        )

    def _step(self, run: RunContext, now_ns: int) -> None:
        assert self.session is not None
        began = time.perf_counter()
        fleet = self.fleet
        session = self.session
        session.move_robots(fleet.x, fleet.y, fleet.yaw)
        session.step(now_ns / NS_PER_S)
        robots = np.column_stack([fleet.x, fleet.y, fleet.radius_m])
        sumo = session.people()
        xy, pushed = push_out(
            np.column_stack([sumo.x_m, sumo.y_m]), self.cfg.worker_radius_m, self.boxes
        )
        self.pushed += pushed
        sumo = replace(sumo, x_m=xy[:, 0], y_m=xy[:, 1])
        walkers = self._keep_clear(sumo, robots) if self.cfg.avoid_robots else sumo
        drivers = session.vehicles() if self.cfg.forklifts else None
        self._publish(walkers, drivers)
        if self.cfg.avoid_robots:
            self._pace(sumo, robots, session)
            if drivers is not None and drivers.names:
                self._pace_forklifts(drivers, robots, session)
        self.steps += 1
        self.coupling_s += time.perf_counter() - began
        self.records.sample(now_ns, self.people)

    def _keep_clear(self, walkers: Movers, robots: FloatArray) -> Movers:
        """Walkers where they may be seen: never walked into a robot.

        SUMO's step from each walker's last published position is cut where it would come
        within the margin of a robot (:func:`models.humans.avoidance.safe_step`); someone
        who appears inside a robot's reach steps aside. The speed model keeps SUMO's own
        steps clear, so a cut is the exception (``humans_steps_cut``); the walker is held
        where the cut left them until SUMO's position is clear again.
        """
        n = len(walkers.names)
        xy = np.column_stack([walkers.x_m, walkers.y_m])
        radii = np.full(n, self.cfg.worker_radius_m)
        last = self.last_xy
        known = np.array([name in last for name in walkers.names], dtype=bool)
        start = np.array(
            [last.get(name, (np.nan, np.nan)) for name in walkers.names], dtype=float
        ).reshape(-1, 2)
        moved = np.zeros(n, dtype=bool)
        if known.any():
            xy[known], moved[known] = safe_step(start[known], xy[known], radii[known], robots)
        if (~known).any():
            xy[~known], moved[~known] = step_aside(xy[~known], radii[~known], robots)
        speed = walkers.speed_mps.copy()
        if moved.any():
            step = np.where(known, np.hypot(*(xy - start).T), 0.0)
            speed[moved] = np.nan_to_num(step[moved]) / (self.step_ns / NS_PER_S)
        self.cut += int(moved.sum())
        self.last_xy = {
            name: (x, y) for name, (x, y) in zip(walkers.names, xy.tolist(), strict=True)
        }
        return replace(walkers, x_m=xy[:, 0], y_m=xy[:, 1], speed_mps=speed)

    def _pace(self, walkers: Movers, robots: FloatArray, session: SumoSession) -> None:
        """Each walker's speed for SUMO's next step: the collision-free speed model."""
        staying = walkers.staying if walkers.staying is not None else np.zeros(0, dtype=bool)
        rows = np.flatnonzero(~staying)
        if len(rows) == 0:
            return
        xy = np.column_stack([walkers.x_m[rows], walkers.y_m[rows]])
        yaw = walkers.yaw_rad[rows]
        radii = np.full(len(rows), self.cfg.worker_radius_m)
        limit = speed_limit(
            free_distance(xy, yaw, radii, robots),
            np.full(len(rows), np.inf),
            room_m=room(xy, yaw, radii, robots),
            step_s=self.step_ns / NS_PER_S,
        )
        names = [walkers.names[k] for k in rows.tolist()]
        session.pace(names, limit)
        stopped = {name for name, v in zip(names, limit.tolist(), strict=True) if v < WAIT_MPS}
        self.yields += len(stopped - self.waiting)
        self.waiting = stopped

    def _pace_forklifts(self, drivers: Movers, robots: FloatArray, session: SumoSession) -> None:
        """Each forklift's speed for SUMO's next step: the same speed model, front disc ahead.

        SUMO's car-following brakes only for a robot's mirror ahead on the forklift's own
        lane; the speed model sees every robot's true footprint, beside the lane and on
        junctions too.
        """
        n = len(drivers.names)
        length, width = self.cfg.forklift_size_m
        cx, cy = vehicle_centres(drivers.x_m, drivers.y_m, drivers.yaw_rad, length)
        front = two_disc_cover(cx, cy, drivers.yaw_rad, length, width)[:n]
        limit = speed_limit(
            free_distance(front[:, :2], drivers.yaw_rad, front[:, 2], robots),
            np.full(n, np.inf),
            room_m=room(front[:, :2], drivers.yaw_rad, front[:, 2], robots),
            step_s=self.step_ns / NS_PER_S,
        )
        session.pace_vehicles(drivers.names, limit)
        stopped = {
            name for name, v in zip(drivers.names, limit.tolist(), strict=True) if v < WAIT_MPS
        }
        self.forklift_yields += len(stopped - self.forklifts_waiting)
        self.forklifts_waiting = stopped

    def _publish(self, walkers: Movers, drivers: Movers | None) -> None:
        cfg = self.cfg
        people = self.people
        xy = np.column_stack([walkers.x_m, walkers.y_m])
        discs = [np.column_stack([xy, np.full(len(walkers.names), cfg.worker_radius_m)])]
        names = list(walkers.names)
        kinds = ["person"] * len(names)
        x, y, yaw, speed = [walkers.x_m], [walkers.y_m], [walkers.yaw_rad], [walkers.speed_mps]
        if drivers is not None and drivers.names:
            length, width = cfg.forklift_size_m
            cx, cy = vehicle_centres(drivers.x_m, drivers.y_m, drivers.yaw_rad, length)
            discs.append(two_disc_cover(cx, cy, drivers.yaw_rad, length, width))
            names += list(drivers.names) * 2
            kinds += ["forklift"] * (2 * len(drivers.names))
            x.append(cx)
            y.append(cy)
            yaw.append(drivers.yaw_rad)
            speed.append(drivers.speed_mps)
        people.discs = np.vstack(discs)
        people.disc_names = names
        self.dynamic.update("humans", people.discs, names, kinds)
        people.names = list(walkers.names) + (list(drivers.names) if drivers is not None else [])
        people.kinds = ["person"] * len(walkers.names) + ["forklift"] * (
            len(people.names) - len(walkers.names)
        )
        people.x_m = np.concatenate(x)
        people.y_m = np.concatenate(y)
        people.yaw_rad = np.concatenate(yaw)
        people.speed_mps = np.concatenate(speed)

    def close(self) -> None:
        """Stop SUMO and keep its files (and log) for the run folder's ``sumo/``."""
        if self.session is not None:
            self.session.close()
        if self.folder.is_dir():
            for path in sorted(self.folder.iterdir()):
                if path.suffix in (".xml", ".sumocfg", ".log") and path.stat().st_size > 0:
                    self.recorder.add_file(f"sumo/{path.name}", path.read_bytes())
            shutil.rmtree(self.folder, ignore_errors=True)

    def finish(self, run: RunContext) -> Mapping[str, Any]:
        """People metrics and the coupling's cost."""
        summary = self.records.summary(run)
        summary.update(
            {
                "humans_workers": self.cfg.workers,
                "humans_standing": len(self.cfg.standing),
                "humans_forklifts": self.cfg.forklifts,
                "humans_sumo_steps": self.steps,
                "humans_pushed_out": self.pushed,
                "humans_yields": self.yields,
                "humans_steps_cut": self.cut,
                "humans_forklift_yields": self.forklift_yields,
                "humans_trips": self.session.arrivals if self.session else 0,
                "humans_coupling_wall_s": round(self.coupling_s, 4),
                "humans_sumo_in_process": bool(self.session and self.session.in_process),
            }
        )
        return summary


Spots = tuple[IntArray, FloatArray]
"""Places on the aisle graph: edge indices and offsets along them (m)."""


def _demand(run: RunContext, graph: AisleGraph, stations: Spots, docks: Spots) -> list[Plan]:
    """Every worker's, forklift's and standing worker's plan, from ``humans/demand``."""
    cfg = run.settings(HumansConfig)
    rng = run.rng.stream("humans/demand")
    duration_s = run.settings(ScenarioSection).duration_s
    demand: list[Plan] = []
    movers: tuple[tuple[Literal["worker", "forklift"], int, float], ...] = (
        ("worker", cfg.workers, cfg.worker_speed_mps),
        ("forklift", cfg.forklifts, cfg.forklift_speed_mps),
    )
    for kind, count, speed in movers:
        demand += plans(
            graph,
            stations,
            docks,
            kind=kind,
            count=count,
            duration_s=duration_s,
            speed_mps=speed,
            stay_s=cfg.pick_s,
            rng=rng,
        )
    standing = np.array(cfg.standing, dtype=float).reshape(-1, 2)
    try:
        return demand + standing_plans(graph, standing, duration_s)
    except ModelError as error:
        raise model_problem(run.scenario.source, error) from None


def _graph(run: RunContext, world: Warehouse) -> tuple[AisleGraph, Spots, Spots]:
    cfg = run.settings(HumansConfig)
    try:
        graph = aisle_graph(
            world,
            clearance_m=cfg.worker_radius_m + CLEARANCE_MARGIN_M,
            spacing_m=cfg.aisle_spacing_m,
        )
        stations = pick_stations(world, graph, cfg.stations, run.rng.stream("humans/stations"))
    except ModelError as error:
        # the graph is asked for the radius plus a margin: name what the user wrote
        value = cfg.worker_radius_m if error.key == "humans.worker_radius_m" else None
        raise model_problem(run.scenario.source, error, value=value) from None
    return graph, stations, dock_points(graph)

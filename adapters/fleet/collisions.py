"""The collision adapter: ground-truth contacts, clearances and near misses (python-fcl).

It guards every physics step of the fleet: the proposed poses are checked against walls,
shelves, other robots and dynamic obstacles; a robot whose proposed pose overlaps
anything is held at its last pose with zero velocity ("stopped": it never passes
through nor jumps). Robots held back may in turn block others, so holding repeats until
no robot moves into contact. Each new contact is a row in ``tables/collisions`` (t_s,
robot, other, kind = wall | shelf | obstacle | robot | person | forklift | dynamic, depth_m,
speed_mps: the robot's speed in the step that touched, 0 when something moved into a
robot at rest) and an event; the smallest clearance over the run and the near misses
(clearance below ``NEAR_MISS_M``) go into the summary.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np
import numpy.typing as npt

from adapters.fleet.motion import FleetAdapter
from cosim.core.adapter import RunContext
from cosim.core.summary import SummaryKey
from cosim.core.table import TableSpec
from cosim.core.timebase import NS_PER_S
from models.fleet.collision import CollisionChecker, OtherKind, Proximity
from models.fleet.kinematics import FleetState, Motion
from models.world.obstacles import DynamicObstacles
from models.world.warehouse import Warehouse

NEAR_MISS_M = 0.1
"""Clearance below which two things count as a near miss (m)."""
COLLISIONS = TableSpec(
    "collisions",
    "One row per new contact of a robot with anything (the robot is held, never passes through).",
    {
        "t_s": "when the contact began (s)",
        "robot": "the robot",
        "other": "what it touched: wall_i, shelf_i, obstacle_i (world.obstacles), another "
        "robot's name, a person's id",
        "kind": "wall, shelf, obstacle, robot, or the kind of a moving thing (person, forklift)",
        "depth_m": "how far the step would have gone into it (m)",
        "speed_mps": "the robot's commanded speed at the contact (m/s): 0 means it stood still",
    },
    categorical=("robot", "other", "kind"),
)
COLLISION_COLUMNS = tuple(COLLISIONS.columns)

Pair = tuple[int, int, int]
"""(robot, kind, other) of a pair in contact or near each other."""


@dataclass(frozen=True)
class ContactCounts:
    """A service of the run: every robot's contacts so far, as they happen.

    Attributes:
        by_robot: new contacts of each robot (fleet order), the rows of
            ``tables/collisions`` counted by robot.
    """

    by_robot: npt.NDArray[np.int64]


class CollisionsAdapter:
    """Checks every proposed fleet step for contacts and holds robots that would collide."""

    name: ClassVar[str] = "collisions"
    requires: ClassVar[tuple[str, ...]] = ("world", "fleet")
    tables: ClassVar[tuple[TableSpec, ...]] = (COLLISIONS,)
    """The tables it writes (documented in the table reference)."""
    summary_keys: ClassVar[Mapping[str, SummaryKey]] = {
        "collisions": SummaryKey(
            "count", "contacts of a robot with anything (rows of tables/collisions)"
        ),
        "near_misses": SummaryKey(
            "count", f"times a robot came closer than {NEAR_MISS_M:g} m to anything"
        ),
        "min_clearance_m": SummaryKey(
            "m", "smallest clearance between a robot and anything (null: never checked)"
        ),
    }
    """The summary keys :meth:`finish` writes (documented in the summary reference)."""

    def __init__(self, run: RunContext) -> None:
        world = run.service(Warehouse)
        self.fleet = run.service(FleetState)
        self.dynamic = run.service(DynamicObstacles)
        self.checker = CollisionChecker(world.boxes, self.fleet.radius_m, margin_m=NEAR_MISS_M)
        walls = [f"wall_{i}" for i in range(len(world.walls))]
        shelves = [f"shelf_{i}" for i in range(len(world.shelves))]
        obstacles = [f"obstacle_{i}" for i in range(len(world.obstacles))]
        # in the order of world.boxes, which the checker's static indices count
        self.static_names = walls + shelves + obstacles
        self.static_kinds = (
            ["wall"] * len(walls) + ["shelf"] * len(shelves) + ["obstacle"] * len(obstacles)
        )
        self.table = run.recorder.table(COLLISIONS)
        self.recorder = run.recorder
        self.contacts: set[Pair] = set()
        self.near: set[Pair] = set()
        self.collisions = 0
        self.near_misses = 0
        self.min_clearance_m = np.inf
        self.counts = ContactCounts(np.zeros(len(self.fleet), dtype=np.int64))
        run.provide(self.counts)
        run.service(FleetAdapter).add_guard(self.guard)

    def start(self, run: RunContext) -> None:
        """Nothing to schedule: the adapter runs inside the fleet's physics step."""

    def _other(self, p: Proximity) -> tuple[str, str]:
        if p.kind is OtherKind.STATIC:
            return self.static_names[p.other], self.static_kinds[p.other]
        if p.kind is OtherKind.ROBOT:
            return self.fleet.names[p.other], "robot"
        return self.dynamic.names[p.other], self.dynamic.kind(p.other)

    def guard(self, now_ns: int, motion: Motion) -> None:
        """Hold robots whose proposed pose overlaps something; record new contacts.

        The broad phase runs once per step. Holding a robot moves it back by one step;
        while that is shorter than the near-miss margin, every pair that holding can
        bring closer than the margin is a candidate already (see
        :meth:`CollisionChecker.evaluate`) and re-evaluating the candidates exactly is
        enough; longer steps re-run the broad phase.
        """
        checker = self.checker
        proposed_v = motion.v.copy()
        candidates = checker.candidates(motion.x, motion.y, self.dynamic.discs)
        gaps = checker.gaps(candidates, motion.x, motion.y)
        final, least = checker.summarize(gaps)
        attempted = [p for p in final if p.clearance_m < 0]
        held = np.zeros(len(motion.x), dtype=bool)
        # ``least`` is the smallest clearance of every candidate pair: unless it is negative
        # nothing overlaps and nobody would be held (most steps skip the loop's array work)
        if least < 0:
            while True:
                touching = np.zeros_like(held)
                for group in gaps:
                    touching[group.robots_in_contact()] = True
                new = touching & ~held
                if not new.any():  # what is left overlapped already before the step
                    break
                held |= new
                self.fleet.hold(motion, np.flatnonzero(new))
                shift = np.hypot(motion.x - candidates.x, motion.y - candidates.y).max()
                if shift > checker.margin_m:
                    candidates = checker.candidates(motion.x, motion.y, self.dynamic.discs)
                gaps = checker.gaps(candidates, motion.x, motion.y)
        if held.any():
            final, least = checker.summarize(gaps)
        # pairs farther apart than the margin only matter until a closer one was seen; and
        # the floor is never below ``checker.floor_min_m``, so once the smallest clearance is
        # at or below that, the floor cannot lower it (its FCL distance queries are skipped)
        if (
            self.min_clearance_m >= NEAR_MISS_M
            and least >= NEAR_MISS_M
            and self.min_clearance_m > checker.floor_min_m
        ):
            least = min(least, checker.floor(candidates))
        self.min_clearance_m = min(self.min_clearance_m, least)
        near = {(p.robot, p.kind.value, p.other) for p in final}
        self._record_contacts(now_ns, attempted, proposed_v)
        # a contact lasts until the pair is farther apart than the near-miss margin again,
        # so a robot creeping against a wall is one collision, not one per step
        self.contacts &= near
        self.near_misses += len(near - self.near)
        self.near = near

    def _record_contacts(
        self, now_ns: int, attempted: list[Proximity], proposed_v: np.ndarray
    ) -> None:
        for p in attempted:
            pair = (p.robot, p.kind.value, p.other)
            if pair in self.contacts:
                continue
            self.contacts.add(pair)
            other, kind = self._other(p)
            robot = self.fleet.names[p.robot]
            self.table.append(
                t_s=now_ns / NS_PER_S,
                robot=robot,
                other=other,
                kind=kind,
                depth_m=-p.clearance_m,
                speed_mps=float(proposed_v[p.robot]),
            )
            self.recorder.event(now_ns, robot, "collision", f"{kind} {other}, robot stopped")
            self.collisions += 1
            self.counts.by_robot[p.robot] += 1

    def finish(self, run: RunContext) -> Mapping[str, Any]:
        """Collisions, near misses and the smallest clearance (m; None if never checked)."""
        least = float(self.min_clearance_m)
        return {
            "collisions": self.collisions,
            "near_misses": self.near_misses,
            "min_clearance_m": round(least, 6) if np.isfinite(least) else None,
        }

"""Random reachable goals for every robot, through the navigation interface.

Until tasks exist, each robot gets a stream of goals: a free cell of the inflated static
map, drawn from the robot's own random stream, in the same connected free region as the
robot; a new one when the previous is reached or reported stuck (as a fleet manager would
re-target a stalled robot), and a second after one is found unreachable. With
``navigation.goals`` the goals are that series instead, in order and round again (robot
``i`` starts at goal ``i``), as the paper's Scenario 2 sends its robot through a series of
goal poses.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any, ClassVar

import numpy as np
from scipy import ndimage

from adapters.navigation.settings import NavigationConfig
from adapters.navigation.topics import goal_topic, status_topic
from cosim.core.adapter import RunContext
from cosim.core.bus import Envelope
from cosim.core.errors import ConfigError
from cosim.core.hosts import HostId
from cosim.core.messages import Message, NavGoal, NavStatus
from cosim.core.summary import SummaryKey
from cosim.core.timebase import s_to_ns
from cosim.scenario.sections import RobotsConfig, WorldConfig
from models.fleet.kinematics import FleetState
from models.navigation.costmap import StaticCostmap

GOAL_CLEARANCE_M = 0.3
"""Free space kept around a goal beyond the footprint (m)."""
RETRY_S = 1.0
"""After a goal found unreachable, the next goal goes out this much later (s)."""


def goal_cells(static: StaticCostmap, radius_m: float, fleet: FleetState) -> list[np.ndarray]:
    """The cells each robot may be sent to: free ones of its own connected region.

    A goal cell keeps :data:`GOAL_CLEARANCE_M` beyond the footprint from every obstacle
    and lies in the free region the robot stands in (robots in one region share one array).

    Args:
        static: the inflated static map.
        radius_m: the robots' footprint radius (m).
        fleet: the robots, where they start.

    Returns:
        Per robot, the (k, 2) cells ``(iy, ix)`` it may be sent to (k = 0: none).
    """
    free = static.distance_m >= radius_m + GOAL_CLEARANCE_M
    labels, _ = ndimage.label(static.cost < 253, structure=np.ones((3, 3)))
    # the goal cells of each region, found once and shared by the robots in it (a
    # list per robot grows with robots x floor: 16 GB for 1,000 robots in 100 m x 100 m)
    by_region: dict[int, np.ndarray] = {0: np.zeros((0, 2), dtype=np.int64)}
    cells: list[np.ndarray] = []
    for x, y in zip(fleet.x, fleet.y, strict=True):
        ix, iy = static.world_to_cell((x, y))
        label = int(labels[iy, ix])
        if label not in by_region:
            by_region[label] = np.argwhere(free & (labels == label))  # (k, 2) as (iy, ix)
        cells.append(by_region[label])
    return cells


class GoalsAdapter:
    """Sends each robot random reachable goals, one after another."""

    name: ClassVar[str] = "goals"
    requires: ClassVar[tuple[str, ...]] = ("navigation",)
    summary_keys: ClassVar[Mapping[str, SummaryKey]] = {
        "goals_sent": SummaryKey("count", "navigation goals sent to the robots"),
    }
    """The summary keys :meth:`finish` writes (documented in the summary reference)."""

    def __init__(self, run: RunContext) -> None:
        fleet = run.service(FleetState)
        self.names = list(fleet.names)
        self.hosts = [HostId(n) for n in self.names]
        static = run.service(StaticCostmap)
        self.static = static
        self.cells = goal_cells(static, run.settings(RobotsConfig).radius_m, fleet)
        width, height = run.settings(WorldConfig).size_m
        for x, y in run.settings(NavigationConfig).goals:
            if not (0 <= x <= width and 0 <= y <= height):
                raise ConfigError(
                    f"{run.scenario.source}: [navigation] goals has [{x:g}, {y:g}]: expected "
                    f"points inside the room [0, {width:g}] x [0, {height:g}] m"
                )
        self.rngs = [run.rng.stream(f"goals/{n}") for n in self.names]
        self.retry_ns = s_to_ns(RETRY_S)
        self.next_id = np.zeros(len(self.names), dtype=np.int64)
        self.sent = 0
        for name in self.names:
            run.bus.advertise(goal_topic(name), NavGoal)

    def start(self, run: RunContext) -> None:
        """Listen to every robot's navigation status and send the first goals."""
        for i, (name, host) in enumerate(zip(self.names, self.hosts, strict=True)):
            run.bus.subscribe(status_topic(name), host, self._on_status(run, i))
        for i in range(len(self.names)):
            self._send(run, i)

    def _on_status(self, run: RunContext, i: int) -> Callable[[Message, Envelope], None]:
        def on_status(message: Message, _envelope: Envelope) -> None:
            assert isinstance(message, NavStatus)
            current = message.goal_id == self.next_id[i] - 1
            if current and message.state in ("arrived", "stuck"):
                self._send(run, i)
            elif current and message.state == "unreachable":
                # the next goal a moment later: a robot whose goals all are unreachable
                # (one stranded in a pocket) would otherwise be sent goal after goal within
                # one instant, each answered at once, without end
                run.kernel.at(run.kernel.now_ns + self.retry_ns, retry(int(self.next_id[i])))

        def retry(sent: int) -> Callable[[], None]:
            def send() -> None:
                if self.next_id[i] == sent:  # no goal went out meanwhile
                    self._send(run, i)

            return send

        return on_status

    def _send(self, run: RunContext, i: int) -> None:
        series = run.settings(NavigationConfig).goals
        if series:
            x, y = series[(i + int(self.next_id[i])) % len(series)]
            self._publish(run, i, x, y)
            return
        cells = self.cells[i]
        if not len(cells):
            return
        iy, ix = cells[int(self.rngs[i].integers(len(cells)))]
        x, y = self.static.cell_to_world((int(ix), int(iy)))
        self._publish(run, i, float(x), float(y))

    def _publish(self, run: RunContext, i: int, x: float, y: float) -> None:
        goal = NavGoal(run.kernel.now_ns, int(self.next_id[i]), x, y)
        self.next_id[i] += 1
        self.sent += 1
        run.bus.publish(goal_topic(self.names[i]), goal, self.hosts[i])

    def finish(self, run: RunContext) -> Mapping[str, Any]:
        """Goals sent."""
        return {"goals_sent": self.sent}

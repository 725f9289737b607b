"""A sequential single-item auction: robots share their bids, then every robot runs the auction.

Every robot bids its own travel cost on every task it may serve and broadcasts the bids it
knows (its own and those it heard); bids spread through the robots' network as the
neighbours pass them on. Once a robot has heard nothing new for the network's diameter plus
``sequential_auction.settle_rounds`` rounds, it auctions the tasks one at a time, each to
the cheapest robot still without a task (ties: fleet order), as every other robot does with
the same bids: a sequential single-item auction (Lagoudakis et al., "Auction-Based
Multi-Robot Routing", Robotics: Science and Systems 2005), here with one task per robot.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar, Literal

import numpy as np

from adapters.assignment.contract import EpochView, ProtocolAgent, ProtocolBase, ProtocolFleet
from cosim.core.messages import Float64s, Message, Time, ros_message, string, uint32
from cosim.scenario.fields import param
from models.arrays import FloatArray


@dataclass(frozen=True)
class AuctionSettings:
    """``[sequential_auction]``: how robots settle their bids and auction the tasks."""

    settle_rounds: int = param(
        1,
        "rounds without news, beyond the network's diameter, before auctioning",
        ge=0,
        le=100,
        unit="rounds",
    )
    order: Literal["task_id", "cheapest_first"] = param(
        "task_id", "auction order: the tasks in id order, or the cheapest bid first"
    )


@ros_message("labkit_msgs/msg/BidTable")
class BidTable(Message):
    """The bids a robot knows: costs (m) of robots (rows) for tasks (columns), inf unknown."""

    stamp_ns: Time
    epoch: uint32
    robot: string
    robots: uint32
    tasks: uint32
    costs: Float64s


class AuctionAgent:
    """One robot's side of the auction in one epoch."""

    def __init__(self, epoch: EpochView, patience: int, order: str) -> None:
        self.epoch = epoch
        self.patience = patience
        self.order = order
        self.bids: FloatArray = np.full(epoch.problem.cost.shape, np.inf)
        self.bids[epoch.robot] = epoch.problem.cost[epoch.robot]
        self.quiet = 0
        self._rounds = 0
        self._won: dict[int, int] = {}

    def round(self, inbox: list[Message], now_ns: int) -> tuple[Message | None, bool]:
        """Take the lowest of every known bid and the neighbours'; pass the table on."""
        before = self.bids.copy()
        for message in inbox:
            if isinstance(message, BidTable) and message.costs:
                heard = np.asarray(message.costs).reshape(message.robots, message.tasks)
                if heard.shape == self.bids.shape:
                    np.minimum(self.bids, heard, out=self.bids)
        changed = not np.array_equal(before, self.bids)
        self._rounds += 1
        # the first round only sends: the neighbours' bids come from the next one on
        self.quiet = 0 if changed or self._rounds == 1 else self.quiet + 1
        if changed or self._rounds == 1:
            self._won = self._auction()
        rows, cols = self.bids.shape
        table = BidTable(
            now_ns,
            self.epoch.epoch,
            self.epoch.name,
            rows,
            cols,
            tuple(self.bids.ravel().tolist()),
        )
        return table, changed

    def _auction(self) -> dict[int, int]:
        """Task by task, each to the cheapest robot without one (robot -> task)."""
        bids = self.bids
        won: dict[int, int] = {}
        tasks = list(range(bids.shape[1]))
        if self.order == "cheapest_first":
            tasks.sort(key=lambda j: (float(bids[:, j].min()), j))
        for j in tasks:
            free = [i for i in range(bids.shape[0]) if i not in won and np.isfinite(bids[i, j])]
            if free:
                won[min(free, key=lambda i: (bids[i, j], i))] = j
        return won

    @property
    def decided(self) -> bool:
        """No news for the network's diameter plus the settling rounds."""
        return self.quiet >= self.patience

    def task(self) -> int | None:
        """The task this robot wins in its auction."""
        return self._won.get(self.epoch.robot)

    @property
    def rounds(self) -> int:
        """Rounds run so far."""
        return self._rounds

    def cost(self) -> float:
        """The winning bids' sum (m)."""
        return float(sum(self.bids[i, j] for i, j in self._won.items()))

    def view(self) -> dict[int, int]:
        """Who wins what, as this robot sees it."""
        return dict(self._won)


class SequentialAuction(ProtocolBase):
    """Sequential single-item auction (Lagoudakis et al. 2005) over bids shared by gossip."""

    name: ClassVar[str] = "sequential_auction"
    message: ClassVar[type[Message] | None] = BidTable
    topic: ClassVar[str | None] = "/fleet/dta/auction_bids"
    compare_to_optimum: ClassVar[bool] = True

    def __init__(self, fleet: ProtocolFleet) -> None:
        super().__init__(fleet)
        self.settings = fleet.run.settings(AuctionSettings)

    def agent(self, epoch: EpochView) -> ProtocolAgent:
        """This robot's auction agent."""
        patience = self.fleet.diameter + self.settings.settle_rounds
        return AuctionAgent(epoch, patience, self.settings.order)

"""``agent_bids``: task assignment where each robot serves what its learning agent bids for.

An assignment protocol (``assignment.protocol = "agent_bids"``, registered in
``cosim.protocols`` as cosim's own are) for the ``bid`` action kind. Every time a robot hears
a new epoch (the open tasks, over the network from the base station), the epoch is handed to
its agent (:attr:`~adapters.agents.contract.AgentView.epochs`: the ``tasks`` observation
part shows it), which may be woken (``agents.wake_on = ["task"]``). Once the agent has
decided after the epoch reached it, the robot claims the free task of the first
``agents.task_slots`` it bids highest for (:func:`models.agents.bids.highest_bid`); claims,
the drive, service and conflicts are the task assignment's, as for every protocol. No
messages are exchanged: the claims are the coordination, as with ``greedy``.
"""

from __future__ import annotations

from typing import ClassVar

from adapters.agents.contract import AgentView
from adapters.assignment.contract import EpochView, ProtocolAgent, ProtocolBase
from cosim.core.errors import ConfigError
from cosim.core.messages import Message
from models.agents.bids import highest_bid


class AgentBids(ProtocolBase):
    """Each robot claims the free task its learning agent bids highest for."""

    name: ClassVar[str] = "agent_bids"

    def agent(self, epoch: EpochView) -> ProtocolAgent:
        """Hand the epoch to the robot's agent; decide once the agent has bid on it."""
        run = self.fleet.run
        if not run.has_service(AgentView):
            raise ConfigError(
                f"{run.scenario.source}: [assignment] protocol = 'agent_bids': expected "
                "robots.driver = 'agents' with agents.action = 'bid' (learning agents bid)"
            )
        view = run.service(AgentView)
        i, now = epoch.robot, run.kernel.now_ns
        view.epochs[i] = epoch
        view.epoch_ns[i] = now
        if "task" in view.settings.wake_on:
            view.woken_ns[i] = now
        return BidAgent(view, epoch, now)


class BidAgent:
    """One robot's side of an epoch: waits for its agent's bids, then claims."""

    def __init__(self, view: AgentView, epoch: EpochView, opened_ns: int) -> None:
        self.agents = view
        self.epoch = epoch
        self.opened_ns = opened_ns
        self.choice: int | None = None
        self._decided = False
        self._rounds = 0

    def round(self, inbox: list[Message], now_ns: int) -> tuple[Message | None, bool]:
        """Claim once the agent has decided since the epoch reached the robot."""
        self._rounds += 1
        i = self.epoch.robot
        if self._decided or self.agents.decided_ns[i] <= self.opened_ns:
            return None, False
        free = set(range(len(self.epoch.tasks))) - set(self.epoch.taken)
        self.choice = highest_bid(self.agents.bids[i], self.epoch.problem.cost[i], free)
        self._decided = True
        return None, True

    @property
    def decided(self) -> bool:
        """Whether the agent has bid on this epoch."""
        return self._decided

    def task(self) -> int | None:
        """The free task bid highest for, or None."""
        return self.choice

    @property
    def rounds(self) -> int:
        """Rounds run so far."""
        return self._rounds

    def cost(self) -> float:
        """The robot's travel cost to its choice (m)."""
        if self.choice is None:
            return 0.0
        return float(self.epoch.problem.cost[self.epoch.robot, self.choice])

    def view(self) -> dict[int, int]:
        """Only this robot's own choice."""
        return {} if self.choice is None else {self.epoch.robot: self.choice}

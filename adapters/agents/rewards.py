"""cosim's own reward terms, registered in ``cosim.agent_rewards`` as a plugin's are.

Each is a running total per agent; an agent's reward for a decision is the weighted
change of the terms since its previous one (``agents.rewards``; each term's ``weight``
unless ``agents.reward_weights`` gives them).
"""

from __future__ import annotations

from typing import ClassVar

import numpy as np

from adapters.agents.contract import AgentView
from adapters.tasks.source import TaskSourceAdapter
from cosim.core.timebase import NS_PER_S
from models.arrays import FloatArray


class Progress:
    """``progress``: metres gained towards the agent's goals (straight line; lost backing off)."""

    name: ClassVar[str] = "progress"
    weight: ClassVar[float] = 1.0

    def __init__(self, view: AgentView) -> None:
        """Nothing to keep: the view holds the goals."""

    def total(self, view: AgentView) -> FloatArray:
        """Progress towards earlier goals plus the current goal's gain (m)."""
        return view.progress_base_m + view.goal_start_m - view.goal_distance_m()


class Arrived:
    """``arrived``: goals reached."""

    name: ClassVar[str] = "arrived"
    weight: ClassVar[float] = 10.0

    def __init__(self, view: AgentView) -> None:
        """Nothing to keep: the view counts arrivals."""

    def total(self, view: AgentView) -> FloatArray:
        """Arrivals so far."""
        return view.arrivals.astype(float)


class Time:
    """``time``: seconds of simulated time (weigh it negative to hurry the agents)."""

    name: ClassVar[str] = "time"
    weight: ClassVar[float] = -0.1

    def __init__(self, view: AgentView) -> None:
        self.ones = np.ones(len(view))

    def total(self, view: AgentView) -> FloatArray:
        """The run's time, for every agent (s)."""
        return self.ones * (view.now_ns / NS_PER_S)


class Contact:
    """``contact``: new contacts with anything (rows of ``tables/collisions``)."""

    name: ClassVar[str] = "contact"
    weight: ClassVar[float] = -5.0

    def __init__(self, view: AgentView) -> None:
        """Nothing to keep: the collision checks count contacts."""

    def total(self, view: AgentView) -> FloatArray:
        """Contacts so far."""
        return view.contacts.astype(float)


class Messages:
    """``messages``: poses the agent broadcast to the others (weigh it to price the air)."""

    name: ClassVar[str] = "messages"
    weight: ClassVar[float] = -0.01

    def __init__(self, view: AgentView) -> None:
        """Nothing to keep: the view counts broadcasts."""

    def total(self, view: AgentView) -> FloatArray:
        """Broadcasts so far."""
        return view.sent.astype(float)


class Tasks:
    """``tasks``: tasks the agent's robot served to the end (the bid action's reward)."""

    name: ClassVar[str] = "tasks"
    weight: ClassVar[float] = 10.0

    def __init__(self, view: AgentView) -> None:
        self.index = {name: i for i, name in enumerate(view.names)}
        self.count = len(view)

    def total(self, view: AgentView) -> FloatArray:
        """Tasks completed so far, by the robot that served them (0 without tasks)."""
        totals = np.zeros(self.count)
        if not view.run.has_service(TaskSourceAdapter):
            return totals
        for task in view.run.service(TaskSourceAdapter).book.tasks.values():
            if task.completed_ns >= 0 and task.server in self.index:
                totals[self.index[task.server]] += 1
        return totals

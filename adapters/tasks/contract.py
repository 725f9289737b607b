"""What the task source needs from whoever assigns its tasks: claim rules, a central solver.

The task source keeps the book of claims and grants service (:mod:`models.tasks.book`);
how long a claim lasts, whether a later epoch may take a task from a robot heading to it,
how often task sets are sent again, and whether a central solver on the base station
orders the robots, are the assignment's to say. A settings section says so by declaring
:meth:`ClaimRulesSection.claim_rules` (the ``[assignment]`` section does); a central
solver is a service of the run (:class:`CentralOrders`), provided by the adapter that runs
it and asked for at every announcement with the open tasks and the free robots' reported
positions (``map``, m).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any, Protocol, runtime_checkable

from cosim.core.messages import TaskInfo


@dataclass(frozen=True)
class ClaimRules:
    """How the task source keeps its book.

    Attributes:
        claim_timeout_s: a claim not repeated for this long is released (s).
        rebroadcast_s: period of re-sending an unchanged task set (s).
        preemption: a robot heading to its task may be re-assigned by a later epoch.
        central: a central solver orders the robots (:class:`CentralOrders`); the robots
            report their poses on ``/fleet/robot_reports`` and get orders on
            ``/<robot>/task_order``.
    """

    claim_timeout_s: float = 5.0
    rebroadcast_s: float = 1.0
    preemption: bool = False
    central: bool = False


@runtime_checkable
class ClaimRulesSection(Protocol):
    """A settings section that says how the task book is kept (``[assignment]``)."""

    def claim_rules(self) -> ClaimRules:
        """The rules the task source keeps its book by."""
        ...


def claim_rules(sections: Mapping[str, Any]) -> ClaimRules:
    """The rules a section declares, or the defaults."""
    for section in sections.values():
        if isinstance(section, ClaimRulesSection):
            return section.claim_rules()
    return ClaimRules()


class CentralSolver(Protocol):
    """Orders for the free robots, from the open tasks and their reported positions."""

    def orders(
        self, tasks: Sequence[TaskInfo], poses: Mapping[str, tuple[float, float]]
    ) -> dict[str, tuple[int, float]]:
        """Robot -> (task id, cost in m) for the robots it assigns."""
        ...


@dataclass(frozen=True)
class CentralOrders:
    """The run's central solver (a service, with :attr:`ClaimRules.central`).

    Attributes:
        solver: what the task source asks for orders.
    """

    solver: CentralSolver

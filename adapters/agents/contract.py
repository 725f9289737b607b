"""What learning agents' pluggable parts are: observation parts, action kinds, reward terms.

Each is a class registered by name in its entry-point group and chosen in ``[agents]``:

- an **observation part** (``cosim.agent_observations``, ``agents.observe``) fills a slice
  of every agent's observation vector: it declares the slice's bounds (``low``, ``high``,
  one number each) and :meth:`ObservationPart.observe` writes every agent's values at once;
- an **action kind** (``cosim.agent_actions``, ``agents.action``) declares what an agent
  may do (:class:`BoxSpec` or :class:`ChoiceSpec`) and applies the actions of the agents
  deciding (:meth:`ActionKind.apply`);
- a **reward term** (``cosim.agent_rewards``, ``agents.rewards``) is a running total per
  agent since the episode began (metres of progress, arrivals, seconds); an agent's reward
  for a decision is the weighted change of every term since its previous decision, so
  agents deciding at different instants are rewarded for their own intervals.

Every class is built once per episode with the :class:`AgentView` (a service of the run
that the ``agents`` adapter provides) and reads the run through it. Times are kernel
nanoseconds, positions metres in ``map``, headings radians.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar, Protocol

import numpy as np

from adapters.agents.settings import AgentsConfig
from cosim.core.adapter import RunContext
from cosim.core.registry import Group
from models.arrays import Float32Array, FloatArray, IntArray
from models.fleet.kinematics import DriveLimits, FleetState


@dataclass
class AgentView:
    """What agents' observation parts, action kinds and reward terms read and drive.

    Arrays are indexed by agent (fleet order) and updated in place as the run goes.

    Attributes:
        run: the run (settings, services, kernel, bus).
        settings: the ``[agents]`` section.
        names: the agents' robot names.
        fleet: the robots' ground truth.
        limits: the robots' drive limits.
        room_m: the room's width and height (m).
        goal_xy: each agent's goal (n, 2) in ``map`` (m).
        goal_start_m: each goal's straight-line distance when it was set (m).
        progress_base_m: progress made towards earlier goals (m).
        arrivals: goals reached so far.
        contacts: contacts so far (every new contact with a shelf, wall, robot or person).
        sent: poses each agent broadcast so far.
        received: poses each agent heard so far.
        places: the places an agent may choose (k, 2) in ``map`` (m) (the goal action).
        ranges_m: each agent's latest lidar ranges (n, beams), ``range_max_m`` where
            nothing returned; (n, 0) without a lidar.
        range_max_m: the lidar's range (m).
        heard_xy: ``heard_xy[i, j]``: the position agent ``i`` last heard from ``j`` (m).
        heard_stamp_ns: when ``j`` sent it (ns; -1: never heard).
        heard_recv_ns: when it reached ``i`` (ns; -1: never heard).
        decided_ns: each agent's latest decision (ns).
        woken_ns: the latest event each agent is woken by (``agents.wake_on``; -1: none).
        bids: each agent's latest bids (n, ``agents.task_slots``) in [0, 1] (the bid action).
        epochs: each agent's latest epoch of open tasks (an
            :class:`~adapters.assignment.contract.EpochView`; None before its first), from
            the ``agent_bids`` assignment protocol.
        epoch_ns: when each agent's latest epoch reached it (ns; -1: none yet).
    """

    run: RunContext
    settings: AgentsConfig
    names: list[str]
    fleet: FleetState
    limits: DriveLimits
    room_m: tuple[float, float]
    goal_xy: FloatArray
    goal_start_m: FloatArray
    progress_base_m: FloatArray
    arrivals: IntArray
    contacts: IntArray
    sent: IntArray
    received: IntArray
    places: FloatArray
    ranges_m: FloatArray
    range_max_m: float
    heard_xy: FloatArray
    heard_stamp_ns: IntArray
    heard_recv_ns: IntArray
    decided_ns: IntArray
    woken_ns: IntArray
    bids: FloatArray
    epochs: list[Any]
    epoch_ns: IntArray

    def __len__(self) -> int:
        return len(self.names)

    @property
    def now_ns(self) -> int:
        """The kernel's time (ns)."""
        return self.run.kernel.now_ns

    def goal_distance_m(self) -> FloatArray:
        """Each agent's straight-line distance to its goal (m)."""
        fleet = self.fleet
        distance: FloatArray = np.hypot(self.goal_xy[:, 0] - fleet.x, self.goal_xy[:, 1] - fleet.y)
        return distance


@dataclass(frozen=True)
class BoxSpec:
    """Actions that are vectors of numbers within bounds (Gymnasium's ``Box``).

    Attributes:
        low: lower bounds, one per component.
        high: upper bounds, one per component.
        names: what each component is, with its unit (for the docs and tables).
    """

    low: tuple[float, ...]
    high: tuple[float, ...]
    names: tuple[str, ...]


@dataclass(frozen=True)
class ChoiceSpec:
    """Actions that are one of ``n`` choices, numbered from 0 (Gymnasium's ``Discrete``)."""

    n: int


# -- observation parts ----------------------------------------------------------------------
class ObservationPart(Protocol):
    """What a ``cosim.agent_observations`` entry point names: a class built once per episode.

    Attributes:
        name: the registered name (in ``agents.observe``).
        low: the lower bound of each of its numbers (shape ``(size,)``).
        high: the upper bound of each (same shape); every value observed lies within.
    """

    name: ClassVar[str]
    low: FloatArray
    high: FloatArray

    def __init__(self, view: AgentView) -> None: ...

    def observe(self, view: AgentView, out: Float32Array) -> None:
        """Write every agent's values into ``out`` (shape ``(agents, size)``, float32)."""
        ...


def _part_contract(name: str, loaded: Any) -> str | None:
    if not isinstance(loaded, type):
        return "is not a class (built with an AgentView)"
    if not callable(getattr(loaded, "observe", None)):
        return "has no observe() method (see adapters.agents.contract.ObservationPart)"
    return None


OBSERVATIONS = Group(
    "cosim.agent_observations",
    "agent observation part",
    "agent observation parts",
    "`adapters.agents.contract` (`ObservationPart`)",
    "`agents.observe`",
    check=_part_contract,
)
"""Observation parts of learning agents (``agents.observe``)."""


# -- action kinds ---------------------------------------------------------------------------
class ActionKind(Protocol):
    """What a ``cosim.agent_actions`` entry point names: a class built once per episode.

    Attributes:
        name: the registered name (``agents.action``).
        adapters: the adapters it needs besides ``agents`` (``navigation`` to drive to a
            chosen place).
        spec: what one agent may do.

    It may declare ``goals: ClassVar[bool] = False``: the agents have no goals of the
    agents adapter's (the ``bid`` action: their tasks are their goals), and no arrivals are
    counted.
    """

    name: ClassVar[str]
    adapters: ClassVar[tuple[str, ...]]
    spec: BoxSpec | ChoiceSpec

    def __init__(self, view: AgentView) -> None: ...

    def apply(self, view: AgentView, agents: IntArray, actions: np.ndarray) -> None:
        """Act for ``agents`` (indices) with ``actions`` (one row each, as :attr:`spec`)."""
        ...


def _action_contract(name: str, loaded: Any) -> str | None:
    if not isinstance(loaded, type):
        return "is not a class (built with an AgentView)"
    if not callable(getattr(loaded, "apply", None)):
        return "has no apply() method (see adapters.agents.contract.ActionKind)"
    if not isinstance(getattr(loaded, "adapters", None), tuple):
        return "has no adapters tuple (the adapters it needs besides agents; () for none)"
    return None


ACTIONS = Group(
    "cosim.agent_actions",
    "agent action kind",
    "agent action kinds",
    "`adapters.agents.contract` (`ActionKind`)",
    "`agents.action`",
    check=_action_contract,
)
"""What learning agents do (``agents.action``)."""


# -- reward terms ---------------------------------------------------------------------------
class RewardTerm(Protocol):
    """What a ``cosim.agent_rewards`` entry point names: a class built once per episode.

    Attributes:
        name: the registered name (in ``agents.rewards``).
        weight: its weight unless ``agents.reward_weights`` gives one (1 if undeclared).
    """

    name: ClassVar[str]
    weight: ClassVar[float]

    def __init__(self, view: AgentView) -> None: ...

    def total(self, view: AgentView) -> FloatArray:
        """Every agent's running total since the episode began (shape ``(agents,)``)."""
        ...


def _reward_contract(name: str, loaded: Any) -> str | None:
    if not isinstance(loaded, type):
        return "is not a class (built with an AgentView)"
    if not callable(getattr(loaded, "total", None)):
        return "has no total() method (see adapters.agents.contract.RewardTerm)"
    return None


REWARDS = Group(
    "cosim.agent_rewards",
    "agent reward term",
    "agent reward terms",
    "`adapters.agents.contract` (`RewardTerm`)",
    "`agents.rewards`",
    check=_reward_contract,
)
"""Reward terms of learning agents (``agents.rewards``)."""


@dataclass(frozen=True)
class AgentParts:
    """The parts ``[agents]`` chooses, built for one episode (a service of the run).

    Attributes:
        action: the action kind.
        observations: the observation parts, in ``agents.observe`` order.
        rewards: the reward terms, in ``agents.rewards`` order.
        weights: each term's weight (``agents.reward_weights``).
    """

    action: ActionKind
    observations: tuple[ObservationPart, ...]
    rewards: tuple[RewardTerm, ...]
    weights: FloatArray


# -- policies -------------------------------------------------------------------------------
class Policy(Protocol):
    """What a ``cosim.agent_policies`` entry point names: a class built once per run.

    A policy decides for every agent in a plain run (``cosim run``, a study), where no
    learning environment does: at every decision the agents adapter observes, asks
    :meth:`act`, checks the actions and applies them.

    Attributes:
        name: the registered name (``agents.policy``).
    """

    name: ClassVar[str]

    def __init__(self, view: AgentView, parts: AgentParts, observation_size: int) -> None: ...

    def act(self, observations: Float32Array) -> np.ndarray:
        """Every agent's action for its observation (one row each, as the action's spec)."""
        ...


def _policy_contract(name: str, loaded: Any) -> str | None:
    if not isinstance(loaded, type):
        return "is not a class (built with an AgentView, the AgentParts and a size)"
    if not callable(getattr(loaded, "act", None)):
        return "has no act() method (see adapters.agents.contract.Policy)"
    return None


POLICIES = Group(
    "cosim.agent_policies",
    "agent policy",
    "agent policies",
    "`adapters.agents.contract` (`Policy`)",
    "`agents.policy`",
    check=_policy_contract,
)
"""Who decides for learning agents in a plain run (``agents.policy``)."""

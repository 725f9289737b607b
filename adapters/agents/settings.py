"""``[agents]``: robots driven by learning agents (``robots.driver = "agents"``).

A learning environment (:mod:`cosim.envs`), or in a plain run the ``policy``, drives every
robot through this section: at each decision an agent sees the observation parts
``observe`` names, acts through the action kind ``action`` names (a velocity, a place to
drive to, bids for open tasks), and is rewarded by the weighted ``rewards``. Each agent has
a goal (a free place of the room drawn from its own random stream, or
``navigation.goals`` in turn) and tells the others its pose over the scenario's network
at ``share_hz``, so what an agent hears of the others comes late or not at all as the
network says.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass
from typing import ClassVar, Literal

from cosim.core.registry import group_named
from cosim.scenario.choices import choice_problems
from cosim.scenario.fields import Problem, param

Wake = Literal["arrival", "message", "contact", "task"]

MIN_RATE_HZ = 1e-3
"""The slowest pose broadcast (Hz): one every 1,000 s."""


@dataclass(frozen=True)
class AgentsConfig:
    """``[agents]``: what learning agents see, do and are rewarded for, and when they decide."""

    ORDER: ClassVar[int] = 65
    """In a resolved scenario file, after ``[navigation]``."""

    decision_hz: float = param(
        10.0, "decisions per second of simulated time, every agent (Hz)", gt=0, le=1000
    )
    observe: tuple[str, ...] = param(
        ("velocity", "goal", "lidar", "inbox"),
        "the observation parts each agent sees, in this order (cosim.agent_observations)",
        registry="cosim.agent_observations",
    )
    action: str = param(
        "velocity",
        "what an agent does: 'velocity' (forward speed and yaw rate), 'goal' (a place the "
        "navigation drives to) or 'bid' (bids for open tasks, with assignment.protocol = "
        "'agent_bids') (cosim.agent_actions)",
        registry="cosim.agent_actions",
    )
    rewards: tuple[str, ...] = param(
        ("progress", "arrived", "time", "contact"),
        "the reward terms (cosim.agent_rewards), weighted by reward_weights",
        registry="cosim.agent_rewards",
    )
    reward_weights: tuple[float, ...] = param(
        (),
        "the weight of each reward term, in the order of rewards (per metre, per arrival, "
        "per second, per contact, ...); empty: each term's own default weight (progress 1, "
        "arrived 10, time -0.1, contact -5, messages -0.01)",
        ge=-1e6,
        le=1e6,
        unit="weight",
    )
    wake_on: tuple[Wake, ...] = param(
        (),
        "events that make an agent decide before its next period, in the event-driven "
        "(AEC) environment: 'arrival' (its goal reached), 'message' (a pose heard), "
        "'contact', 'task' (a new set of open tasks reached it: the bid action)",
    )
    stagger: bool = param(
        False,
        "spread the agents' decision instants evenly over a period (the event-driven AEC "
        "environment: agents decide one by one, not all at once)",
    )
    goal_tolerance_m: float = param(
        0.25,
        "an agent within this distance of its goal has arrived (m): navigation's own default",
        gt=0,
        le=100,
    )
    lidar_bins: int = param(
        16,
        "lidar observation: sectors of the scan, the nearest return in each",
        ge=1,
        le=4096,
        unit="count",
    )
    share_hz: float = param(
        5.0,
        "how often each agent broadcasts its pose to the others over the network (Hz; 0: "
        "never, the inbox stays empty)",
        ge=0,
        le=1000,
    )
    inbox_max_age_s: float = param(
        2.0,
        "inbox observation: news older than this is forgotten; the age observed is "
        "clipped to it (s)",
        gt=0,
        le=3600,
    )
    policy: str = param(
        "none",
        "who decides in a plain run (cosim run, a study): 'none' (an environment of cosim.envs "
        "decides; without one the robots stand still), 'random', or 'sb3' (a trained "
        "Stable-Baselines3 model) (cosim.agent_policies)",
        registry="cosim.agent_policies",
        off="none",
    )
    policy_file: str = param("", "sb3 policy: the model file (saved by model.save)", path=True)
    sb3_algorithm: str = param(
        "PPO", "sb3 policy: the model's Stable-Baselines3 class (PPO, A2C, SAC, TD3, DQN)"
    )
    task_slots: int = param(
        4,
        "bid action: the open tasks an agent bids for (the first of each epoch it hears)",
        ge=1,
        le=64,
        unit="count",
    )
    places: int = param(
        8,
        "goal action: the places an agent can choose among (drawn per episode)",
        ge=1,
        le=256,
        unit="count",
    )

    def adapters(self) -> list[str]:
        """What the action kind needs besides the ``agents`` adapter (``navigation``)."""
        kind = group_named("cosim.agent_actions").installed().get(self.action)
        return list(getattr(kind, "adapters", ()))

    def problems(self) -> Iterator[Problem]:
        """A weight for every reward term; a part observed once; what the policy needs."""
        yield from choice_problems(self, "policy")
        if self.reward_weights and len(self.reward_weights) != len(self.rewards):
            yield Problem(
                "reward_weights",
                list(self.reward_weights),
                f"{len(self.rewards)} weights, one for each of rewards {list(self.rewards)}",
            )
        if len(set(self.observe)) != len(self.observe):
            yield Problem("observe", list(self.observe), "each part named once")
        if len(set(self.rewards)) != len(self.rewards):
            yield Problem("rewards", list(self.rewards), "each term named once")
        if not self.observe:
            yield Problem("observe", [], "at least one observation part")
        if 0 < self.share_hz < MIN_RATE_HZ:
            yield Problem("share_hz", self.share_hz, f"0 (never) or >= {MIN_RATE_HZ:g} Hz")

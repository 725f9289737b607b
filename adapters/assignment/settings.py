"""The ``[assignment]`` section: how robots decide who serves which task."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar, Literal

from adapters.tasks.contract import ClaimRules
from cosim.core.registry import group_named
from cosim.scenario.fields import param


@dataclass(frozen=True)
class AssignmentConfig:
    """``[assignment]``: how robots decide who serves which task."""

    ORDER: ClassVar[int] = 80
    """Where the section comes in a resolved scenario and in the adapters' order."""

    protocol: str = param(
        "distributed_simplex",
        "a registered assignment protocol: 'distributed_simplex' (Buerger et al. 2012, as in "
        "ChoiRbot), 'hungarian' (centralized on the base station), 'greedy' (nearest free "
        "task) or 'cbba' (consensus-based auction, Choi et al. 2009)",
        registry="cosim.protocols",
    )
    period_ms: float = param(100.0, "protocol round period (ms)", gt=0)
    round_phase: Literal["independent", "aligned"] = param(
        "independent",
        "robots' round timers: each started at its own random phase within the period, as "
        "timers on separate machines are, or all firing at the same instants",
    )
    preemption: bool = param(
        False, "a robot heading to its task may be re-assigned by a later epoch"
    )
    diameter_bound: int = param(
        0,
        "bound on the robot graph's diameter for halting; 0 = from the topology",
        ge=0,
        unit="hops",
    )
    cost: Literal["euclidean", "path"] = param(
        "euclidean", "task cost: straight-line distance, or shortest path on the static map"
    )
    claim_timeout_s: float = param(
        5.0, "a claim not repeated for this long is released by the task source (s)", gt=0
    )
    rebroadcast_s: float = param(
        1.0, "period of re-sending task sets, claims and unchanged protocol state (s)", gt=0
    )

    def claim_rules(self) -> ClaimRules:
        """How the task source keeps its book (:mod:`adapters.tasks.contract`)."""
        central = group_named("cosim.protocols").installed().get(self.protocol).central
        return ClaimRules(
            claim_timeout_s=self.claim_timeout_s,
            rebroadcast_s=self.rebroadcast_s,
            preemption=self.preemption,
            central=bool(central),
        )

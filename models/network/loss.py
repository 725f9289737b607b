"""Per-link packet loss processes, driven by uniforms supplied by the caller.

Each process decides one packet at a time from two uniforms in [0, 1): ``u_transition``
(for processes with a state) and ``u_loss``. Handing the uniforms in lets the caller
fetch them in blocks from the link's own random stream. A process with a state belongs
to exactly one directed link.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Protocol

from models.errors import ModelError


class LossProcess(Protocol):
    """Decides, packet by packet, whether a link loses a packet."""

    def lost(self, u_transition: float, u_loss: float) -> bool:
        """Decide one packet and advance the state once; uniforms in [0, 1)."""
        ...

    def stationary_loss(self) -> float:
        """Long-run fraction of packets lost."""
        ...


def check_probability(key: str, value: float) -> float:
    """Return ``value`` as a float if it is a probability.

    Raises:
        ModelError: ``key`` = value when it is not a number in [0, 1] (NaN included).
    """
    probability = float(value)
    if not 0.0 <= probability <= 1.0:  # also rejects NaN
        raise ModelError(key, value, "a probability in [0, 1]")
    return probability


@dataclass(frozen=True)
class NoLoss:
    """A link that never loses a packet."""

    def lost(self, u_transition: float, u_loss: float) -> bool:
        """Never lost."""
        return False

    def stationary_loss(self) -> float:
        """0."""
        return 0.0

    def mean_burst_length(self) -> float:
        """0: there are no bursts."""
        return 0.0


@dataclass(frozen=True)
class BernoulliLoss:
    """Independent losses: each packet is lost when ``u_loss < p``.

    Attributes:
        p: loss probability (``network.loss_prob``).
    """

    p: float

    def __post_init__(self) -> None:
        check_probability("network.loss_prob", self.p)

    def lost(self, u_transition: float, u_loss: float) -> bool:
        """Lost with probability ``p``; ``u_transition`` is not used."""
        return u_loss < self.p

    def stationary_loss(self) -> float:
        """``p``."""
        return float(self.p)

    def mean_burst_length(self) -> float:
        """``1 / (1 - p)``: runs of losses are geometric (0 if p = 0, inf if p = 1)."""
        if self.p == 0.0:
            return 0.0
        return math.inf if self.p == 1.0 else 1.0 / (1.0 - self.p)


class GilbertElliottLoss:
    """Two-state burst loss, with the meaning and order of Linux netem's ``loss gemodel``.

    ``tc ... netem loss gemodel p r 1-h 1-k`` maps to ``GilbertElliottLoss(p, r,
    loss_good=1-k, loss_bad=1-h)``: ``p`` = P(Good -> Bad), ``r`` = P(Bad -> Good),
    ``1-h`` = loss probability in Bad, ``1-k`` = loss probability in Good. As in tc,
    ``loss_bad`` defaults to 1 and ``loss_good`` to 0 (the Gilbert model), and ``r``
    defaults to ``1 - p``, which with those defaults is Bernoulli loss of rate ``p``.

    Order per packet, as in the kernel's ``loss_gilb_ell`` (net/sched/sch_netem.c): the
    transition uniform is compared first and moves the state, then the loss uniform is
    compared with the loss probability of the state the packet *started in* (the switch
    is on the old state). So packet n is lost according to state S_n, and the transition
    draw decides S_{n+1}. The chain starts in Good.

    Args:
        p: P(Good -> Bad) per packet (``network.ge_p``).
        r: P(Bad -> Good) per packet (``network.ge_r``); ``None`` means ``1 - p``.
        loss_good: loss probability in Good, netem's 1-k (``network.ge_loss_good``).
        loss_bad: loss probability in Bad, netem's 1-h (``network.ge_loss_bad``).

    Raises:
        ModelError: when a parameter is not a probability in [0, 1].
    """

    __slots__ = ("_bad", "loss_bad", "loss_good", "p", "r")

    def __init__(
        self, p: float, r: float | None = None, *, loss_good: float = 0.0, loss_bad: float = 1.0
    ) -> None:
        self.p = check_probability("network.ge_p", p)
        self.r = check_probability("network.ge_r", 1.0 - self.p if r is None else r)
        self.loss_good = check_probability("network.ge_loss_good", loss_good)
        self.loss_bad = check_probability("network.ge_loss_bad", loss_bad)
        self._bad = False

    @property
    def bad(self) -> bool:
        """Whether the next packet starts in the Bad state."""
        return self._bad

    def lost(self, u_transition: float, u_loss: float) -> bool:
        """Decide one packet from its state, then move the state (see class docstring)."""
        if self._bad:
            if u_transition < self.r:
                self._bad = False
            return u_loss < self.loss_bad
        if u_transition < self.p:
            self._bad = True
        return u_loss < self.loss_good

    def stationary_bad(self) -> float:
        """Long-run fraction of packets sent in Bad: ``p / (p + r)``.

        With ``p = r = 0`` the chain never leaves its starting state Good: 0.
        """
        total = self.p + self.r
        return self.p / total if total > 0.0 else 0.0

    def stationary_loss(self) -> float:
        """``pi_G * loss_good + pi_B * loss_bad`` with ``pi_B = p / (p + r)``."""
        bad = self.stationary_bad()
        return (1.0 - bad) * self.loss_good + bad * self.loss_bad

    def mean_burst_length(self) -> float:
        """Mean length of a run of consecutive losses, in packets, in the long run.

        Derivation. Losses are conditionally independent given the states, with
        P(loss | S = s) = e_s. In the stationary regime every burst has one first and one
        last packet, so (number of losses) / (number of bursts) tends to

            P(L_n = 1) / P(L_n = 1, L_{n+1} = 0) = 1 / P(L_{n+1} = 0 | L_n = 1),

        where P(L_n = 1, L_{n+1} = 0) = sum_s pi_s e_s sum_s' P(s -> s') (1 - e_s').
        For the simple Gilbert case (e_G = 0, e_B = 1) this is pi_B r / pi_B, giving 1/r;
        with r = 1 - p and those losses (Bernoulli) it is 1/(1 - p).

        Returns:
            The mean burst length; 0 when nothing is ever lost, ``inf`` when a burst,
            once started, never ends.
        """
        bad = self.stationary_bad()
        good = 1.0 - bad
        e_good, e_bad = self.loss_good, self.loss_bad
        loss = good * e_good + bad * e_bad
        if loss == 0.0:
            return 0.0
        kept_after_good = (1.0 - self.p) * (1.0 - e_good) + self.p * (1.0 - e_bad)
        kept_after_bad = self.r * (1.0 - e_good) + (1.0 - self.r) * (1.0 - e_bad)
        ends = good * e_good * kept_after_good + bad * e_bad * kept_after_bad
        return math.inf if ends == 0.0 else loss / ends

    def __repr__(self) -> str:
        return (
            f"GilbertElliottLoss(p={self.p}, r={self.r}, loss_good={self.loss_good}, "
            f"loss_bad={self.loss_bad})"
        )

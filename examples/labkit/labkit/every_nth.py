"""A loss model: every n-th message on each link is lost, the others all arrive.

A deterministic stand-in for a link with a fixed packet error rate, handy to check by hand
what a protocol does when exactly one message in ``every_nth.n`` goes missing.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import ClassVar

from adapters.network.contract import NetworkContext
from cosim.scenario.fields import param
from models.network.loss import LossProcess


@dataclass(frozen=True)
class EveryNthSettings:
    """``[every_nth]``: the loss model ``network.loss_model = "every_nth"``."""

    n: int = param(
        10, "every n-th message of each directed link is lost", ge=2, le=1_000_000, unit="count"
    )


class EveryNthLoss:
    """The loss process of one directed link: counts its messages, loses the n-th."""

    def __init__(self, n: int) -> None:
        self.n = n
        self.count = 0

    def lost(self, u_transition: float, u_loss: float) -> bool:
        """Whether this message is lost (the random draws are not needed)."""
        self.count += 1
        return self.count % self.n == 0

    def stationary_loss(self) -> float:
        """The long-run loss: one in n."""
        return 1.0 / self.n


class EveryNth:
    """Every n-th message of each directed link is lost (``[every_nth] n``)."""

    name: ClassVar[str] = "every_nth"

    def __init__(self, context: NetworkContext) -> None:
        self.n = context.run.settings(EveryNthSettings).n

    def factory(self) -> Callable[[], LossProcess]:
        """A fresh counter per directed link."""
        return lambda: EveryNthLoss(self.n)

"""The built-in loss models of the ``links`` backend (``network.loss_model``).

Every directed link gets a loss process of its own (:mod:`models.network.loss`); the
parameters of Gilbert-Elliott follow netem's ``loss gemodel p r 1-h 1-k``.
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from typing import ClassVar

from adapters.network.contract import NetworkContext
from models.network.loss import BernoulliLoss, GilbertElliottLoss, LossProcess, NoLoss


class Lossless:
    """No message is lost on a link (range, queues and partitions still drop)."""

    name: ClassVar[str] = "none"

    def __init__(self, context: NetworkContext) -> None:
        pass

    def factory(self) -> Callable[[], LossProcess]:
        """:class:`~models.network.loss.NoLoss` (the ideal network's fast path knows it)."""
        return NoLoss


class Bernoulli:
    """Every message is lost with probability network.loss_prob, independently."""

    name: ClassVar[str] = "bernoulli"
    keys: ClassVar[tuple[str, ...]] = ("loss_prob",)

    def __init__(self, context: NetworkContext) -> None:
        self.prob = context.network.loss_prob
        BernoulliLoss(self.prob)  # refused now, not at the first message

    def factory(self) -> Callable[[], LossProcess]:
        """A :class:`~models.network.loss.BernoulliLoss` per link."""
        return functools.partial(BernoulliLoss, self.prob)


class GilbertElliott:
    """Losses in bursts: a good and a bad state (network.ge_p, ge_r, ge_loss_good, ge_loss_bad)."""

    name: ClassVar[str] = "gilbert_elliott"

    def __init__(self, context: NetworkContext) -> None:
        cfg = context.network
        self.make = functools.partial(
            GilbertElliottLoss,
            cfg.ge_p,
            cfg.ge_r,
            loss_good=cfg.ge_loss_good,
            loss_bad=cfg.ge_loss_bad,
        )
        self.make()  # refused now, not at the first message

    def factory(self) -> Callable[[], LossProcess]:
        """A :class:`~models.network.loss.GilbertElliottLoss` per link, each in the good state."""
        return self.make

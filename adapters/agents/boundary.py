"""Checks at the boundary between cosim and an agent's parts or a learning library.

What a plugin's observation part or reward term hands back is checked before a policy
sees it (a value outside the bounds the part declared, NaN, a wrong shape); what a
learning library hands in as actions is checked before the robots get it.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from adapters.agents.contract import AgentParts, AgentView, BoxSpec, ChoiceSpec
from cosim.core.plugins import refuse
from models.arrays import Float32Array, FloatArray


def observation_problem(
    block: np.ndarray, low: FloatArray, high: FloatArray, names: Sequence[str]
) -> str | None:
    """What is wrong with an observation part's values for every agent, or None.

    Args:
        block: (agents, size) values the part wrote.
        low: its declared lower bounds (size,).
        high: its declared upper bounds (size,).
        names: the agents' names.
    """
    bad = ~np.isfinite(block) | (block < low) | (block > high)
    if not bad.any():
        return None
    i, k = (int(v) for v in np.argwhere(bad)[0])
    return (
        f"observe() wrote {float(block[i, k])!r} for {names[i]} at index {k}: expected a "
        f"finite number within its declared bounds [{float(low[k]):g}, {float(high[k]):g}] "
        f"({int(bad.sum())} value(s) out of {bad.size} wrong)"
    )


def reward_problem(total: object, agents: int) -> str | None:
    """What is wrong with a reward term's running totals, or None."""
    values = np.asarray(total)
    if values.shape != (agents,):
        return f"total() returned shape {values.shape}: expected ({agents},), one per agent"
    if not np.issubdtype(values.dtype, np.number) or not np.isfinite(values).all():
        return f"total() returned {values!r}: expected finite numbers"
    return None


def action_problem(
    spec: BoxSpec | ChoiceSpec, actions: np.ndarray, names: Sequence[str]
) -> str | None:
    """What is wrong with the actions handed in for agents ``names`` (one row each), or None."""
    if isinstance(spec, ChoiceSpec):
        if actions.shape != (len(names),):
            return f"actions of shape {actions.shape}: expected ({len(names)},), a choice each"
        with np.errstate(invalid="ignore"):
            valid = np.isfinite(actions) & (actions == np.round(actions))
            valid &= (actions >= 0) & (actions < spec.n)
        if valid.all():
            return None
        i = int(np.flatnonzero(~valid)[0])
        given = actions[i].item()
        return f"action {given!r} for {names[i]}: expected a whole number 0..{spec.n - 1}"
    size, what = len(spec.low), ", ".join(spec.names)
    if actions.shape != (len(names), size):
        return f"actions of shape {actions.shape}: expected ({len(names)}, {size}) ({what})"
    finite = np.isfinite(actions).all(axis=1)
    if finite.all():
        return None
    i = int(np.flatnonzero(~finite)[0])
    return f"action {actions[i].tolist()!r} for {names[i]}: expected finite numbers ({what})"


def observe_all(parts: AgentParts, view: AgentView, out: Float32Array) -> None:
    """Write every agent's observation into ``out`` (agents, size), part after part.

    Raises:
        PluginError: a part wrote a value outside its declared bounds, or NaN.
        Exception: what a part's own code raised, as it was raised.
    """
    column = 0
    for part in parts.observations:
        size = len(part.low)
        block = out[:, column : column + size]
        part.observe(view, block)
        problem = observation_problem(block, part.low, part.high, view.names)
        if problem is not None:
            raise refuse(part, problem).at(view.now_ns)
        column += size


def reward_totals(parts: AgentParts, view: AgentView) -> FloatArray:
    """(terms, agents) running totals of every reward term.

    Raises:
        PluginError: a term handed back the wrong shape, or values that are not finite.
        Exception: what a term's own code raised, as it was raised.
    """
    totals = np.zeros((len(parts.rewards), len(view)))
    for k, term in enumerate(parts.rewards):
        total = term.total(view)
        problem = reward_problem(total, len(view))
        if problem is not None:
            raise refuse(term, problem).at(view.now_ns)
        totals[k] = total
    return totals

"""Derived metrics: computed from each run's summary metrics when a ``[report]`` names them.

Study validation checks that a report's derived metric has the inputs the runs report
(:func:`cosim.studies.validate.probe`); the report adds it to ``results.parquet``
(:func:`cosim.studies.reporting.add_derived_metrics`).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from types import MappingProxyType

import pandas as pd


@dataclass(frozen=True)
class DerivedMetric:
    """A metric computed from each run's summary metrics when the report names it.

    Attributes:
        inputs: the summary metrics it needs.
        formula: how it is computed, for the report.
        compute: the metric per row of the results (NaN where it is undefined).
    """

    inputs: tuple[str, ...]
    formula: str
    compute: Callable[[pd.DataFrame], pd.Series]


def _wall_us_per_robot_s(results: pd.DataFrame) -> pd.Series:
    robot_s = results["robots"].astype(float) * results["sim_time_s"].astype(float)
    return 1e6 * results["wall_time_s"].astype(float) / robot_s.where(robot_s > 0)


def _goals_per_min(results: pd.DataFrame) -> pd.Series:
    reached = pd.Series(float("nan"), index=results.index)
    for column in ("arrivals", "agent_arrivals"):  # a learning agent's own count wins
        if column in results.columns:
            counted = results[column].astype(float)
            reached = counted.where(counted.notna(), reached)
    minutes = results["sim_time_s"].astype(float) / 60.0
    return reached / minutes.where(minutes > 0)


DERIVED_METRICS: Mapping[str, DerivedMetric] = MappingProxyType(
    {
        "goals_per_min": DerivedMetric(
            inputs=("sim_time_s",),
            formula="goals reached per minute: agent_arrivals (learning agents' goals) or "
            "else arrivals (the navigation's), / (sim_time_s / 60)",
            compute=_goals_per_min,
        ),
        "wall_us_per_robot_s": DerivedMetric(
            inputs=("wall_time_s", "robots", "sim_time_s"),
            formula="wall-clock microseconds per simulated robot-second, "
            "1e6 x wall_time_s / (robots x sim_time_s)",
            compute=_wall_us_per_robot_s,
        ),
    }
)
"""Metrics a ``[report]`` may name besides the runs' own, by name."""

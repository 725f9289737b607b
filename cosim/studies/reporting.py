"""Figures and report.md of a study, from its ``[report]`` section."""

from __future__ import annotations

from pathlib import Path

from cosim.analysis import standard_figures, write_report
from cosim.studies.spec import StudySpec

DEFAULT_METRICS = (
    "tasks_per_min",
    "mean_convergence_time_s",
    "optimality_gap",
    "conflicts",
    "messages_sent",
    "collisions",
)


def report_study(spec: StudySpec, out: Path) -> Path:
    """Write ``figures/*.png`` and ``report.md`` for a finished (or partial) study."""
    report = spec.report
    varied = spec.varied_keys()
    x = report.get("x", varied[0] if varied else None)
    hue = report.get("hue")
    facet = report.get("facet")
    metrics = list(report.get("metrics", DEFAULT_METRICS))
    figures = standard_figures(out, x=x, hue=hue, metrics=metrics, facet=facet)
    return write_report(
        out,
        name=spec.name,
        x=x,
        hue=hue,
        metrics=metrics,
        description=spec.description,
        figures=figures,
        facet=facet,
    )

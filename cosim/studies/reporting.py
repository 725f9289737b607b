"""Figures and report.md of a study, from its ``[report]`` section."""

from __future__ import annotations

from pathlib import Path

from cosim.analysis import FIGURES_DIR, heatmap, load_results, standard_figures, write_report
from cosim.studies.spec import StudySpec
from cosim.studies.timeseries import timeseries_figures

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
    heatmaps = list(report.get("heatmaps", []))
    if heatmaps and x is not None and facet is not None:
        results = load_results(out)
        ok = results[results["status"] == "ok"]
        for metric in heatmaps:
            if metric in ok.columns and ok[metric].notna().any():
                target = out / FIGURES_DIR / f"{metric}_over_{x}_and_{facet}.png"
                figures.append(heatmap(ok, x=x, y=facet, metric=metric, facet=hue, out=target))
    for entry in report.get("timeseries", []):
        figures += timeseries_figures(out, entry, x=x, hue=hue, facet=facet)
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

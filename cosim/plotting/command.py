"""Every figure of a run folder (``cosim plot RUN_DIR``, ``cosim run --figures``)."""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from pathlib import Path

from cosim.core.errors import ExportError
from cosim.plotting.animation import animation_gif
from cosim.plotting.assignment import assignment_figure
from cosim.plotting.maps import has_maps, maps_figure, quality_figure
from cosim.plotting.network import inter_host, network_figure
from cosim.plotting.rundata import RunData, load_run
from cosim.plotting.timeline import timeline_figure
from cosim.plotting.trajectories import snapshots_figure, trajectories_figure

FIGURES_DIR = "figures"
SNAPSHOTS_DEFAULT = 4
"""Snapshots drawn when no time is given."""
SNAPSHOTS_MAX = 12
"""Most snapshot times accepted."""
PAPER_TIMES_S: dict[str, tuple[float, ...]] = {"lab-mixed": (25.0,)}
"""Snapshot times of the paper's figures, by scenario name, added to the default times: the
paper's Scenario 3 (preset ``lab-mixed``) shows the fleet at t = 25 s (VirTooS, Fig. 'Snapshot
of the mixed-reality experiment at t = 25 s')."""


def plot_run(
    run_dir: Path,
    *,
    at: Sequence[float] | None = None,
    gif: bool = False,
    out: Path | None = None,
    note: Callable[[str], object] | None = None,
) -> list[Path]:
    """Draw the figures of a run from its folder alone; return the files written.

    Into ``out`` (default ``RUN_DIR/figures``):

    - ``trajectories.png``: the world and every robot's trajectory (and task stations);
    - ``snapshots.png``: the fleet at the times ``at`` (default: 4 evenly spaced times);
    - ``tasks.png``: the task timeline, if the run has tasks;
    - ``network.png``: messages and latency over time, if messages crossed hosts;
    - ``assignment.png``: convergence per epoch, if the run has assignment rounds;
    - ``maps.png`` and ``map_quality.png``: the robots' maps and their quality over time,
      if the robots mapped;
    - ``run.gif`` with ``gif``: an animation of the run.

    Figures whose data the run lacks are skipped, not drawn empty.

    Args:
        run_dir: a run folder (``cosim run --out``).
        at: snapshot times (s from the start), within the run, at most 12.
        gif: also write the animation.
        out: folder for the files (created if needed).
        note: called with each line on how an older folder was read (a key renamed since,
            a section of a plugin not installed: :attr:`RunData.notes`).

    Returns:
        The files written, in the order above.

    Raises:
        ExportError: ``run_dir`` is not a readable run folder (see
            :func:`~cosim.plotting.rundata.load_run`), a time of ``at`` is outside the run,
            or a file cannot be written; the message names the path or value.
        ConfigError: the run's ``scenario.toml`` is invalid (a folder of any earlier format
            is read: :func:`cosim.runner.runfolder.read_run_scenario`).
        ScenarioError: the run's world cannot be rebuilt.
    """
    run = load_run(Path(run_dir))
    if note is not None:
        for line in run.notes:
            note(line)
    times = snapshot_times(run, at)
    folder = Path(out) if out is not None else run.path / FIGURES_DIR
    written = [
        trajectories_figure(run, folder / "trajectories.png"),
        snapshots_figure(run, times, folder / "snapshots.png"),
    ]
    if run.tasks is not None:
        written.append(timeline_figure(run, folder / "tasks.png"))
    if not inter_host(run).empty:
        written.append(network_figure(run, folder / "network.png"))
    if run.assignments is not None:
        written.append(assignment_figure(run, folder / "assignment.png"))
    if has_maps(run):
        written.append(maps_figure(run, folder / "maps.png"))
        quality = quality_figure(run, folder / "map_quality.png")
        written += [quality] if quality is not None else []
    if gif:
        written.append(animation_gif(run, folder / "run.gif"))
    return written


def snapshot_times(run: RunData, at: Sequence[float] | None) -> list[float]:
    """The snapshot times (s): ``at`` checked against the run, or evenly spaced ones.

    The defaults are ``duration * k / 4`` for k = 1..4, each at most the last pose's time,
    plus, for a scenario of the paper, the times of its figures within the run
    (:data:`PAPER_TIMES_S`: t = 25 s for ``lab-mixed``), in time order.

    Raises:
        ExportError: ``at`` is empty, too long, or has a time that is not a number between
            the first pose and the end of the run.
    """
    first, last = float(run.track.t_s[0]), float(run.track.t_s[-1])
    end = max(last, run.scenario.scenario.duration_s)
    if at is None:
        even = [min(end * k / SNAPSHOTS_DEFAULT, last) for k in range(1, SNAPSHOTS_DEFAULT + 1)]
        paper = PAPER_TIMES_S.get(run.scenario.name, ())
        return sorted({*even, *(t for t in paper if first <= t <= last)})
    times = list(at)
    if not 1 <= len(times) <= SNAPSHOTS_MAX:
        raise ExportError(f"{run.path}: {len(times)} snapshot times: expected 1 to {SNAPSHOTS_MAX}")
    checked = []
    for t in times:
        try:
            value = float(t)
        except (TypeError, ValueError):
            value = math.nan
        if not (math.isfinite(value) and first <= value <= end):
            raise ExportError(
                f"{run.path}: snapshot time {t!r} s: expected a time within the run, "
                f"{first:g} to {end:g} s"
            )
        checked.append(value)
    return checked

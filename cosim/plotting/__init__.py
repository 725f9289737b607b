"""Figures (PNG) and animations (GIF) of runs, drawn from a run's folder alone.

The shell layer's drawing code: matplotlib ``Figure`` objects on the Agg canvas, never
pyplot and its global state, so figures can be drawn from worker processes and tests
without a display and without touching the caller's matplotlib backend.

Modules, one concept each:

- :mod:`~cosim.plotting.command`: :func:`~cosim.plotting.command.plot_run`, every figure
  of a run folder (``cosim plot``);
- :mod:`~cosim.plotting.rundata`: loading and validating a run folder;
- :mod:`~cosim.plotting.canvas`: sizes, colours and writing PNG files;
- :mod:`~cosim.plotting.world`: walls, shelves and obstacles (and ``cosim world --png``);
- :mod:`~cosim.plotting.fleet`: robots, trails and tasks at one instant (snapshots, frames);
- :mod:`~cosim.plotting.trajectories`: trajectories and snapshot grids;
- :mod:`~cosim.plotting.timeline`, :mod:`~cosim.plotting.network`,
  :mod:`~cosim.plotting.assignment`: tasks, network and assignment over time;
- :mod:`~cosim.plotting.rays` and :mod:`~cosim.plotting.animation`: the GIF of a run.

The package imports nothing here on purpose: matplotlib loads only for a figure drawn
(``cosim world --png``, ``cosim map``, ``cosim plot``), never for a run.
"""

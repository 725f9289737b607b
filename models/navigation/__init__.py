"""Navigation: costmaps, global planning and local control (the Nav2 role).

- :mod:`models.navigation.costmap`: Nav2-like static layer (inflated once from an
  occupancy grid) and per-plan dynamic obstacles (lidar points, robot discs).
- :mod:`models.navigation.planner`: A* global planner on a cost grid, path pruning,
  goal checks and the shortest-path length used by the path-length-ratio metric;
  its numba kernels live in :mod:`models.navigation.gridsearch`.
"""

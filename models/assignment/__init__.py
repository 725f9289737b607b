"""Task assignment: which robot serves which task.

Pure: cost matrices in, assignments out, no kernel time. Robots are indexed 0..R-1 and
tasks 0..T-1; ``cost[i, j]`` is robot i's travel cost (m) to task j, ``math.inf`` where
robot i may not serve task j. An assignment maps a robot to at most one task, and no
task appears twice.
"""

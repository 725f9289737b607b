"""Simple robot software without navigation: line-of-sight waypoints, wandering."""

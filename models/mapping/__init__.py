"""Mapping models (the slam_toolbox role): log-odds grids, scan matching, map quality."""

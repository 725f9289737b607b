"""Mapping on every robot (the slam_toolbox role): maps, pose correction, sharing, quality."""

"""Planar geometry every capability shares: angles, rigid transforms, occupancy grids."""

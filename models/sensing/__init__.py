"""Sensing: the planar lidar's beams and error model, and batched exact ray casting."""

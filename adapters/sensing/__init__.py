"""Sensors sampling the ground truth: the batched lidar."""

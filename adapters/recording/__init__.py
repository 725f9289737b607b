"""What a run keeps beyond the bus tap: poses for the tables, the ROS interface for bags.

The ROS interface publishes the clock, frames, ground truth, map and markers that bags
and the live view carry.
"""

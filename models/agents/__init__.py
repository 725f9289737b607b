"""What learning agents observe, computed for every agent at once: frames and sectors."""

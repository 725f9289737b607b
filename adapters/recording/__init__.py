"""What a run keeps beyond the bus tap: ground-truth poses sampled into tables."""

"""The static world: the warehouse generated once per run, and the base-station host."""

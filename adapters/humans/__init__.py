"""People and forklifts co-simulated with SUMO: the adapter and its records."""

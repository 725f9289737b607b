"""SUMO co-simulation: the files SUMO reads and a running SUMO session."""

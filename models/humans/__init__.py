"""People and forklifts in the aisles: the walking graph, demand and encounter metrics."""

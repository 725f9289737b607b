"""Learning agents: robots a Gymnasium or PettingZoo environment drives (``[agents]``)."""

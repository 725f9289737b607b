"""The task source on the base station: tasks created, announced, granted and closed."""

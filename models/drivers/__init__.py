"""Simple robot behaviours a driver runs instead of navigation: go to a goal, wander."""

"""Motion capture in the run: pose sources, their checks, and robots localizing by them."""

"""The Nav2 role on every robot: planning, control, recovery, and random goals."""

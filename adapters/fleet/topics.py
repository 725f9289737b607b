"""Topics of the fleet: what every robot tells the others of itself."""

from __future__ import annotations

ROBOT_STATES = "/fleet/robot_states"
"""RobotState broadcasts of the robots layer (every robot's pose and footprint)."""

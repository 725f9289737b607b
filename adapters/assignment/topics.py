"""Topics of task assignment among the robots (the task source's: adapters.tasks.topics)."""

from __future__ import annotations

BASES = "/fleet/dta/bases"
"""SimplexBasis broadcasts among robots (distributed simplex)."""
BIDS = "/fleet/dta/bids"
"""CbbaBids broadcasts among robots (CBBA)."""
ASSIGNMENT = "/fleet/assignment"
"""TaskAssignment: what each robot's protocol decided (for tools; nothing subscribes)."""

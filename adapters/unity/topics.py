"""Bus topics of what Unity scenes publish into a run."""

from __future__ import annotations

POSE_PREFIX = "/unity"
"""Bus topics of tracked poses from Unity: this prefix, then the topic a scene publishes on."""


def pose_bus_topic(body: str) -> str:
    """The bus topic of the poses a scene publishes on ``body`` (``/unity/robot_1/pose``)."""
    return POSE_PREFIX + body

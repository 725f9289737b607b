"""Hosts: the computers that adapters live on.

A message between two adapters on one host is delivered at once; between hosts it
crosses the link model of that pair.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import StrEnum
from typing import NewType

HostId = NewType("HostId", str)


class HostKind(StrEnum):
    """What a host stands for."""

    ROBOT = "robot"
    """A robot's onboard computer."""
    BASE = "base"
    """The base station / fleet server."""
    MOCAP = "mocap"
    """A motion-capture server."""
    EXTERNAL = "external"
    """Something outside the simulation (a real robot, a bridge)."""


@dataclass(frozen=True, slots=True)
class Host:
    """A computer on the simulated network.

    Attributes:
        id: unique name, e.g. ``robot_3`` or ``base``.
        kind: what the host stands for.
    """

    id: HostId
    kind: HostKind


BASE_HOST = HostId("base")


def robot_host(robot: str) -> HostId:
    """Return the host id of a robot's onboard computer (the robot's own name)."""
    return HostId(robot)

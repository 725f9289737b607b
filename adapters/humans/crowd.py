"""The people and forklifts SUMO moves, as they are now: the humans adapter's service.

The humans adapter (:mod:`adapters.humans.people`) updates one :class:`People` after every
SUMO step and provides it to the run; other adapters read it (the ROS interface's markers),
and so does the humans table (:mod:`adapters.humans.tables`).
"""

from __future__ import annotations

import numpy as np


class People:
    """The people and forklifts now, for other adapters (markers, figures).

    Attributes:
        names: their ids.
        kinds: ``person`` or ``forklift`` per id.
        x_m, y_m, yaw_rad, speed_mps: their poses and speeds (``map``).
        discs, disc_names: the (k, 3) discs ``x_m, y_m, radius_m`` that lidars and collision
            checks see (two per forklift), and whose each disc is.
    """

    def __init__(self) -> None:
        self.names: list[str] = []
        self.kinds: list[str] = []
        self.x_m = np.zeros(0)
        self.y_m = np.zeros(0)
        self.yaw_rad = np.zeros(0)
        self.speed_mps = np.zeros(0)
        self.discs = np.zeros((0, 3))
        self.disc_names: list[str] = []
        self.forklift_size_m = (0.0, 0.0)
        self.worker_radius_m = 0.0

"""A task's life in synthetic tables: claimed, released, claimed again, served.

Task 0: robot_1 claims it at 1 s, releases it at 10 s; robot_2 claims it at 12 s and
completes it at 20 s. Task 1: robot_1 claims it at 2 s, releases it at 15 s, no one else
takes it.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

STATION = (2.0, 3.0)
"""Task 0's station (m, ``map``)."""
FLEET = tuple(f"robot_{i}" for i in range(1, 10))
"""The robots whose events may give a task up (robot_1 to robot_9)."""


def tasks_table() -> pd.DataFrame:
    return pd.DataFrame(
        {
            "task": [0.0, 1.0],
            "x_m": [STATION[0], 5.0],
            "y_m": [STATION[1], 5.0],
            "t_created_s": [0.0, 0.0],
            "t_assigned_s": [1.0, 2.0],
            "robot": ["robot_2", ""],
            "t_started_s": [18.0, np.nan],
            "t_completed_s": [20.0, np.nan],
        }
    )


def navigation_table() -> pd.DataFrame:
    return pd.DataFrame(
        {
            "t_s": [1.0, 2.0, 12.0],
            "robot": ["robot_1", "robot_1", "robot_2"],
            "event": ["goal", "goal", "goal"],
            "goal_x_m": [STATION[0], 5.0, STATION[0]],
            "goal_y_m": [STATION[1], 5.0, STATION[1]],
        }
    )


def events_table() -> pd.DataFrame:
    return pd.DataFrame(
        {
            "t_s": [10.0, 15.0],
            "source": ["robot_1", "robot_1"],
            "kind": ["release", "release"],
            "detail": ["task 0: stuck", "task 1: stuck"],
        }
    )

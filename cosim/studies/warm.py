"""Imported by the study workers' fork server: tie it to the study, load every kernel once.

Study workers fork from a server process; whatever it has loaded, they start with. First the
server asks to die with the study that started it (:mod:`cosim.studies.lifeline`), so a
study killed outright leaves nothing running. Then running one tiny scenario here loads the
numba kernels (lidar, planner, local controller, simplex) from their cache once, instead of
once in every worker.
"""

from __future__ import annotations

from cosim.runner.execute import execute
from cosim.scenario import load_scenario
from cosim.studies.lifeline import bind_fork_server

_TINY = {
    "scenario.duration_s": 0.5,
    "world.size_m": [12.0, 12.0],
    "world.shelf_count": 2,
    "robots.count": 2,
    "tasks.initial": 1,
    "lidar.beams": 36,
    "record.messages": False,
}

bind_fork_server()
execute(load_scenario("warehouse-random", _TINY))

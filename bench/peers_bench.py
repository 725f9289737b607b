"""cosim beside a peer simulator, measured in the same command: IR-SIM-X on the fleet50 hall.

IR-SIM-X (pip ``irsim-x`` 1.1.4, IR-SIM with a C++ core) simulates kinematics and lidar only.
``make bench-peers`` installs it in ``bench/peers/.venv`` (a virtual environment of its own,
so that its numpy and shapely never meet cosim's) and runs ``bench/run.py --only peers``.
Each repetition runs, in turn: IR-SIM-X's hall (50 robots driving to goals, 360-beam 10 m
lidar every step, ``steps`` steps of 0.1 s) in a subprocess, then cosim's physics, preset
and whole stack in this process. Ratios are taken within a repetition (both sides measured
back to back), then the median across repetitions, so that a machine's drift cancels.
"""

from __future__ import annotations

import json
import statistics
import subprocess
import tempfile
from pathlib import Path
from typing import Any

from cases import FULL_STACK

import cosim
from adapters.world.warehouse import scenario_warehouse

Result = dict[str, Any]

PEER_VENV = Path(__file__).resolve().parent / "peers" / ".venv"
PEER_SCRIPT = Path(__file__).resolve().parent / "peers" / "irsim_hall.py"
PEER_VERSION = "1.1.4"
STEPS, STEP_S = 100, 0.1


def hall(scenario: cosim.Scenario) -> dict[str, Any]:
    """The hall of ``scenario`` as the peer reads it: boxes, starts, goals (m, ``map``)."""
    world = scenario_warehouse(scenario)
    starts = world.starts
    # each robot's goal: the start of the robot across the dock, moved north into the hall,
    # so that every robot crosses shelves' lidar shadows (IR-SIM's 'dash' drives straight)
    goals = starts.copy()
    goals[:, 0] = starts[::-1, 0]
    goals[:, 1] = world.size_m[1] - starts[:, 1]
    robots, lidar = scenario.robots, scenario.lidar
    return {
        "size_m": list(world.size_m),
        "boxes": world.boxes.tolist(),
        "starts": starts.tolist(),
        "goals": goals.tolist(),
        "radius_m": robots.radius_m,
        "speed_mps": robots.max_speed_mps,
        "beams": lidar.beams,
        "range_m": lidar.range_max_m,
    }


def _peer_python() -> Path:
    python = PEER_VENV / "bin" / "python"
    if not python.exists():
        raise SystemExit(
            f"bench peers: {python} is missing; `make bench-peers` installs irsim-x "
            f"{PEER_VERSION} there"
        )
    return python


def _peer_run(hall_file: Path) -> Result:
    done = subprocess.run(
        [str(_peer_python()), str(PEER_SCRIPT), str(hall_file), str(STEPS), str(STEP_S)],
        capture_output=True,
        text=True,
        check=False,
    )
    if done.returncode != 0:
        raise SystemExit(f"bench peers: irsim-x failed:\n{done.stderr[-2000:]}")
    result: Result = json.loads(done.stdout.strip().splitlines()[-1])
    return result


def irsim_peer(repeat: int) -> Result:
    """fleet50: IR-SIM-X's physics vs cosim's physics, preset and whole stack, same run.

    cosim's cases run on every core (``threads`` = the cores available, as ``cosim run``
    does), the whole stack also on one thread.
    """
    from suites import SineDriver

    base = cosim.load_scenario("fleet50")
    whole = cosim.load_scenario("fleet50", FULL_STACK)
    cases: dict[str, tuple[cosim.Scenario, bool, int | None]] = {
        "physics": (base, True, None),
        "preset": (base, False, None),
        "whole_stack": (whole, False, None),
        "whole_stack_1_thread": (whole, False, 1),
    }
    rtf: dict[str, list[float]] = {name: [] for name in ["irsim_x", *cases]}
    peer_last: Result = {}
    with tempfile.TemporaryDirectory() as tmp:
        hall_file = Path(tmp) / "hall.json"
        hall_file.write_text(json.dumps(hall(base)))
        for scenario, weave, threads in cases.values():  # numba caches and imports warm
            extra = [SineDriver] if weave else []
            cosim.run(scenario, duration_s=1.0, adapters=extra, threads=threads)
        for _ in range(repeat):
            peer_last = _peer_run(hall_file)
            rtf["irsim_x"].append(peer_last["real_time_factor"])
            for name, (scenario, weave, threads) in cases.items():
                extra = [SineDriver] if weave else []
                result = cosim.run(
                    scenario, seed=5, duration_s=30.0, adapters=extra, threads=threads
                )
                rtf[name].append(float(result.summary["real_time_factor"]))
    ratios = {
        name: [round(c / p, 3) for c, p in zip(rtf[name], rtf["irsim_x"], strict=True)]
        for name in cases
    }
    return {
        "peer": f"irsim-x {PEER_VERSION}: kinematics and lidar only ({STEPS} steps of {STEP_S} s)",
        "cosim_cases": {
            "physics": "kinematics, lidar, collisions, poses; a weaving driver, no bus (30 s)",
            "preset": "fleet50 as it comes: navigation by the PIBT fleet manager (30 s, seed 5)",
            "whole_stack": f"overrides {FULL_STACK} (30 s, seed 5)",
            "whole_stack_1_thread": "the same on one thread (--threads 1)",
        },
        "real_time_factor_all": {k: [round(v, 2) for v in vs] for k, vs in rtf.items()},
        "real_time_factor_median": {k: round(statistics.median(v), 2) for k, v in rtf.items()},
        "ratio_to_irsim_x_all": ratios,
        "ratio_to_irsim_x_median": {k: round(statistics.median(v), 3) for k, v in ratios.items()},
        "irsim_x_last": peer_last,
        "note": "no bag; the run loop's wall time (summary wall_time_s); IR-SIM-X's world "
        "built before its clock starts",
        "repeat": repeat,
    }

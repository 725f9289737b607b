"""Learning environments (cosim.envs): decisions per second, one environment and eight.

Random velocity actions, one decision per 0.1 s of simulated time, whole stack on (360-beam
lidar, collision checks, the agents' pose broadcasts over the network, every table
recorded). One environment of 1, 8 and 50 robots in warehouse-random (30 m x 30 m, 24
shelves), in this process; and Gymnasium's AsyncVectorEnv of 8 lab-room environments of 4
robots each, one process each, on the machine's cores. An agent step is one robot's
decision. Target (issue 48): 8 environments x 4 robots at least 2,000 agent steps/s on two
cores.
"""

from __future__ import annotations

import statistics
import time
from typing import Any

import gymnasium
import numpy as np

import cosim.envs

Result = dict[str, Any]

SECONDS = 8.0
"""Wall-clock seconds each measurement steps for (after a warm-up)."""
TARGET_AGENT_STEPS_S = 2000
ROBOTS = (1, 8, 50)


def _steps_per_second(env: Any, seconds: float) -> float:
    """Environment steps per wall second over ``seconds`` of random actions."""
    env.reset(seed=1)
    space = env.action_space
    space.seed(1)
    for _ in range(10):  # warm-up: the first steps compile and fill caches
        env.step(space.sample())
    steps, start = 0, time.perf_counter()
    while time.perf_counter() - start < seconds:
        _, _, terminated, truncated, _ = env.step(space.sample())
        steps += 1
        if np.any(terminated) or np.any(truncated):
            env.reset()
    return steps / (time.perf_counter() - start)


def _lab_room() -> gymnasium.Env[Any, Any]:
    return gymnasium.make(cosim.envs.ENV_ID, scenario="lab-room", duration_s=600.0)


def envs_steps(repeat: int) -> Result:
    """Agent steps per second: one environment of 1, 8, 50 robots; 8 of 4 in parallel."""
    out: Result = {"decision_hz": 10.0, "seconds_each": SECONDS}
    for n in ROBOTS:
        env = cosim.envs.WarehouseEnv(
            "warehouse-random", overrides={"robots.count": n}, duration_s=600.0
        )
        rates = [_steps_per_second(env, SECONDS) for _ in range(max(repeat, 1))]
        env.close()
        steps = statistics.median(rates)
        out[f"robots_{n}"] = {
            "env_steps_per_s": round(steps, 1),
            "agent_steps_per_s": round(steps * n, 1),
            "sim_s_per_wall_s": round(steps / 10.0, 2),
        }
    rates = []
    for _ in range(max(repeat, 1)):
        vector = gymnasium.vector.AsyncVectorEnv([_lab_room] * 8, context="forkserver")
        rates.append(_steps_per_second(vector, SECONDS) * 8 * 4)
        vector.close()
    agent_steps = statistics.median(rates)
    out["parallel_8x4"] = {
        "agent_steps_per_s": round(agent_steps, 1),
        "range": [round(min(rates), 1), round(max(rates), 1)],
        "target": TARGET_AGENT_STEPS_S,
        "met": agent_steps >= TARGET_AGENT_STEPS_S,
    }
    return out

import itertools

import numpy as np
from pettingzoo.test import api_test

from cosim.envs import WarehouseAECEnv, env


def test_pettingzoos_aec_checker_passes_with_staggered_and_woken_agents():
    overrides = {"agents.stagger": True, "agents.wake_on": ["message", "arrival", "contact"]}
    api_test(env(scenario="lab-room", overrides=overrides, duration_s=3.0), num_cycles=200)


def _decisions(overrides, duration_s=2.0):
    aec = WarehouseAECEnv("lab-room", overrides=overrides, duration_s=duration_s)
    aec.reset(seed=4)
    made = []
    for agent in aec.agent_iter():
        _, _, terminated, truncated, info = aec.last()
        if terminated or truncated:
            aec.step(None)
            continue
        made.append((round(info["t_s"], 6), agent))
        aec.step(np.zeros(2, np.float32))
    return made, aec


def test_staggered_agents_decide_one_by_one_each_at_its_own_period():
    made, _ = _decisions({"agents.stagger": True})
    times = {}
    for t, agent in made:
        times.setdefault(agent, []).append(t)
    assert sorted(times) == ["robot_1", "robot_2", "robot_3", "robot_4"]
    assert times["robot_1"][:3] == [0.0, 0.1, 0.2]
    assert times["robot_2"][:3] == [0.025, 0.125, 0.225]
    assert times["robot_4"][:2] == [0.075, 0.175]
    assert len({t for t, _ in made}) == len(made)  # never two at once


def test_agents_woken_by_messages_decide_when_a_pose_reaches_them():
    latency = {"network.latency_ms": 33.0, "agents.share_hz": 3.0}
    periodic, _ = _decisions(latency)
    woken, aec = _decisions({**latency, "agents.wake_on": ["message"]})
    assert len(woken) > len(periodic)
    messages = aec.result().tables["messages"]
    states = messages[(messages["topic"] == "/agents/states") & (messages["status"] == "delivered")]
    arrivals = set(zip(states["t_recv_s"].round(6), states["dst_host"], strict=True))
    by_agent: dict[str, list[float]] = {}
    for t, agent in woken:
        by_agent.setdefault(agent, []).append(t)
    woken_at = 0
    for agent, times in by_agent.items():
        for before, t in itertools.pairwise(times):
            on_period = abs(t - before - 0.1) < 1e-6
            at_arrival = (t, agent) in arrivals
            assert on_period or at_arrival, (agent, before, t)  # a period on, or woken
            woken_at += at_arrival and not on_period
    assert woken_at > 10

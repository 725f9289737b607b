import numpy as np
import pytest

from cosim.envs import Agents, WarehouseParallelEnv

NS = 1_000_000_000


def _inbox_run(overrides, seed=3, duration_s=3.0):
    env = WarehouseParallelEnv(
        "lab-room", overrides={"agents.observe": ["inbox"], **overrides}, duration_s=duration_s
    )
    obs, _ = env.reset(seed=seed)
    seen = [(0, obs["robot_1"])]
    while env.agents:
        obs, *_ = env.step({a: np.zeros(2, np.float32) for a in env.agents})
        if obs:
            seen.append((env.core.now_ns, obs["robot_1"]))
    return seen, env.result()


@pytest.mark.parametrize("latency_ms", [0.0, 80.0, 260.0])
def test_what_an_agent_heard_is_what_the_network_delivered_before_it_decided(latency_ms):
    overrides = {
        "network.latency_model": "normal",
        "network.latency_ms": latency_ms,
        "network.jitter_ms": latency_ms / 4,
        "network.loss_model": "bernoulli",
        "network.loss_prob": 0.2,
    }
    seen, result = _inbox_run(overrides)
    messages = result.tables["messages"]
    to_me = messages[
        (messages["topic"] == "/agents/states")
        & (messages["dst_host"] == "robot_1")
        & (messages["status"] == "delivered")
    ]
    for t_ns, observation in seen:
        rows = observation.reshape(3, 4)
        for k, peer in enumerate(["robot_2", "robot_3", "robot_4"]):
            heard = to_me[(to_me["src_host"] == peer) & (to_me["t_recv_ns"] < t_ns)]
            if heard.empty:
                assert rows[k, 2] == pytest.approx(2.0) and rows[k, 3] == 0.0
                continue
            latest = heard["t_sent_ns"].max()
            assert rows[k, 2] == pytest.approx((t_ns - latest) / NS, abs=1e-6)


def test_a_latency_sweep_shifts_the_age_of_what_agents_hear():
    ages = {}
    for latency_ms in (0.0, 250.0, 450.0):
        seen, _ = _inbox_run({"network.latency_ms": latency_ms})
        ages[latency_ms] = np.mean([obs.reshape(3, 4)[:, 2].mean() for _, obs in seen[10:]])
    # poses go out every 0.2 s: the freshest one heard is one period older per 0.2 s of latency
    assert ages[250.0] - ages[0.0] == pytest.approx(0.2, abs=0.01)
    assert ages[450.0] - ages[0.0] == pytest.approx(0.4, abs=0.01)


def test_an_agent_never_hears_anything_without_sharing():
    seen, result = _inbox_run({"agents.share_hz": 0.0}, duration_s=1.0)
    assert all((obs.reshape(3, 4)[:, 2] == 2.0).all() for _, obs in seen)
    assert result.summary["agent_poses_sent"] == 0


def test_observations_stay_within_the_declared_bounds_while_robots_crash_about():
    agents = Agents("lab-room", duration_s=15.0)
    agents.reset(seed=8)
    rng = np.random.default_rng(1)
    space = agents.observation_space
    while not agents.ended:
        obs = agents.observe()
        assert np.all(obs >= space.low) and np.all(obs <= space.high)
        ahead = np.column_stack([np.full(4, 0.5), rng.uniform(-0.5, 0.5, 4)])
        agents.act(np.arange(4), ahead)  # full speed, wobbling: into walls and each other
        agents.advance_all()
    assert agents.finish().summary["collisions"] > 0  # random driving touched something

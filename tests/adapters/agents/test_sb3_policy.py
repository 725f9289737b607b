"""The sb3 policy with a real Stable-Baselines3 model (the `rl` extra; skipped without it)."""

import numpy as np
import pytest

import cosim
from cosim.core.errors import ConfigError
from cosim.envs import WarehouseEnv

sb3 = pytest.importorskip("stable_baselines3")

TASK = {
    "robots.count": 1,
    "robots.positions": [[2.0, 1.0, 1.5708]],
    "agents.observe": ["velocity", "goal", "lidar"],
}


@pytest.fixture(scope="module")
def model_file(tmp_path_factory):
    env = WarehouseEnv("lab-room", overrides=TASK, duration_s=5.0)
    model = sb3.PPO("MlpPolicy", env, n_steps=64, batch_size=32, seed=1, device="cpu")
    model.learn(total_timesteps=128)
    path = tmp_path_factory.mktemp("policy") / "tiny.zip"
    model.save(path)
    return path, model


def test_a_saved_model_drives_a_plain_run_as_it_drives_the_environment(model_file):
    path, model = model_file
    scenario = cosim.load_scenario(
        "lab-room",
        {
            **TASK,
            "robots.driver": "agents",
            "agents.policy": "sb3",
            "agents.policy_file": str(path),
        },
    )
    run = cosim.run(scenario, seed=3, duration_s=3.0)
    env = WarehouseEnv("lab-room", overrides=TASK, duration_s=3.0)
    obs, _ = env.reset(seed=3)
    done = False
    while not done:
        action, _ = model.predict(obs, deterministic=True)
        obs, _, _, done, _ = env.step(np.asarray(action, np.float32))
    assert run.tables["poses"].equals(env.result().tables["poses"])


def test_a_model_trained_on_other_observations_is_refused_naming_the_shapes(model_file):
    path, _ = model_file
    scenario = cosim.load_scenario(
        "lab-room",
        {
            **TASK,
            "agents.observe": ["velocity", "goal"],
            "robots.driver": "agents",
            "agents.policy": "sb3",
            "agents.policy_file": str(path),
        },
    )
    with pytest.raises(ConfigError, match=r"observes shape \(1, 21\): expected \(5,\)"):
        cosim.run(scenario, duration_s=1.0)


def test_a_zip_that_is_no_model_is_refused_naming_the_file_not_blamed_on_cosim(tmp_path):
    import zipfile

    fake = tmp_path / "notes.zip"
    with zipfile.ZipFile(fake, "w") as archive:
        archive.writestr("notes.txt", "not a policy")
    scenario = cosim.load_scenario(
        "lab-room",
        {
            **TASK,
            "robots.driver": "agents",
            "agents.policy": "sb3",
            "agents.policy_file": str(fake),
        },
    )
    with pytest.raises(ConfigError, match=r"notes\.zip.*expected a PPO model saved by"):
        cosim.run(scenario, duration_s=1.0)

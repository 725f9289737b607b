import gymnasium

import cosim.envs
from cosim.envs import ENV_ID, WarehouseAECEnv, WarehouseEnv, WarehouseParallelEnv


def test_importing_the_package_registers_the_gymnasium_id_once():
    cosim.envs.register_envs()  # again: no error, one entry
    spec = gymnasium.spec(ENV_ID)
    assert spec.entry_point == "cosim.envs.gym_env:WarehouseEnv"
    assert isinstance(gymnasium.make(ENV_ID, duration_s=0.5).unwrapped, WarehouseEnv)


def test_pettingzoo_conventions_build_the_parallel_and_aec_environments():
    assert isinstance(cosim.envs.parallel_env(duration_s=0.5), WarehouseParallelEnv)
    assert isinstance(cosim.envs.env(duration_s=0.5), WarehouseAECEnv)

"""Train a small policy on cosim/Warehouse-v0 with Stable-Baselines3 PPO: the tutorial's task.

One Jackal in the VirTooS paper's 4 m x 8 m lab room (two boxes in it) drives to goal after
goal: it sees its speed, its goal (ahead, left, distance) and the nearest return in each of
16 lidar sectors, sets its forward speed and yaw rate ten times a second, and is rewarded
per metre of progress, per goal reached, and penalized per second and per contact.

Every ``--eval-every`` training steps the policy drives ``--eval-seeds`` episodes it never
trained on (deterministic actions); the learning curve is the goals it reached per minute,
beside a random policy and cosim's own navigation (a planner and the dwa controller) on the
same episodes. Writes ``learning_curve.csv`` and ``learning_curve.png`` to ``--out`` and the
model to ``--model``; ``make study-agents`` then measures the saved model in a cosim study.

Run ``make train-agent`` (installs the ``rl`` extra) or
``python studies/train_agent.py --steps 300000``.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

import cosim
import cosim.envs
from cosim.envs import WarehouseEnv

SCENARIO = "lab-room"
TASK: dict[str, Any] = {
    "robots.count": 1,
    "robots.positions": [[2.0, 1.0, 1.5708]],
    "agents.observe": ["velocity", "goal", "lidar"],
}
"""The reduced task: one robot of the lab room, its speed, goal and lidar sectors."""
EPISODE_S = 30.0
EVAL_SEED_BASE = 10_000
"""Evaluation episodes use seeds from here on: never a training episode's seed (< 2**31
drawn by the vector env from its own seed, 0 .. n_envs - 1... are the first ones)."""


def evaluate(policy: Any, seeds: list[int]) -> float:
    """Goals per minute a policy reaches over the episodes of ``seeds`` (mean)."""
    env = WarehouseEnv(SCENARIO, overrides=TASK, duration_s=EPISODE_S)
    reached = []
    for seed in seeds:
        obs, _ = env.reset(seed=seed)
        done = False
        while not done:
            obs, _, terminated, truncated, _ = env.step(policy(obs))
            done = terminated or truncated
        reached.append(env.result().summary["agent_arrivals"])
    env.close()
    return float(np.mean(reached)) / (EPISODE_S / 60.0)


def navigation_goals_per_min(seeds: list[int]) -> float:
    """cosim's own navigation (robots.driver = "navigation") on the same episodes.

    The agents adapter draws goals as the goals adapter does, from the same streams: with
    the same seed the navigation is sent to the same goals in the same order, and arrives
    within the same 0.25 m.
    """
    navigation = {k: v for k, v in TASK.items() if not k.startswith("agents.")}
    scenario = cosim.load_scenario(SCENARIO, {**navigation, "robots.driver": "navigation"})
    reached = [
        cosim.run(scenario, seed=seed, duration_s=EPISODE_S).summary["arrivals"] for seed in seeds
    ]
    return float(np.mean(reached)) / (EPISODE_S / 60.0)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=300_000, help="training steps in all")
    parser.add_argument("--envs", type=int, default=8, help="environments in parallel")
    parser.add_argument("--eval-every", type=int, default=25_000)
    parser.add_argument("--eval-seeds", type=int, default=8)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--out", type=Path, default=Path("studies/results/agents_training"))
    parser.add_argument("--model", type=Path, default=Path("studies/policies/lab_goals_ppo.zip"))
    args = parser.parse_args()

    from stable_baselines3 import PPO
    from stable_baselines3.common.callbacks import BaseCallback
    from stable_baselines3.common.env_util import make_vec_env
    from stable_baselines3.common.vec_env import SubprocVecEnv

    args.out.mkdir(parents=True, exist_ok=True)
    seeds = [EVAL_SEED_BASE + k for k in range(args.eval_seeds)]
    rng = np.random.default_rng(args.seed)
    space = WarehouseEnv(SCENARIO, overrides=TASK, duration_s=EPISODE_S).action_space

    def random_policy(_obs: np.ndarray) -> np.ndarray:
        return rng.uniform(space.low, space.high).astype(np.float32)

    started = time.perf_counter()
    baselines = {"random": evaluate(random_policy, seeds)}
    baselines["navigation (dwa)"] = navigation_goals_per_min(seeds)
    print(f"baselines (goals/min): {baselines}", flush=True)

    venv = make_vec_env(
        cosim.envs.ENV_ID,
        n_envs=args.envs,
        seed=args.seed,
        vec_env_cls=SubprocVecEnv,
        vec_env_kwargs={"start_method": "forkserver"},
        env_kwargs={"scenario": SCENARIO, "overrides": TASK, "duration_s": EPISODE_S},
    )
    model = PPO("MlpPolicy", venv, n_steps=512, batch_size=256, seed=args.seed, device="cpu")
    curve: list[dict[str, float]] = []

    def measure(steps: int) -> None:
        def act(obs: np.ndarray) -> np.ndarray:
            return model.predict(obs, deterministic=True)[0]

        rate = evaluate(act, seeds)
        wall = time.perf_counter() - started
        curve.append({"steps": steps, "goals_per_min": rate, "wall_s": round(wall, 1)})
        print(f"{steps:>8} steps  {rate:6.2f} goals/min  {wall:6.0f} s", flush=True)

    class Evaluate(BaseCallback):  # type: ignore[misc]
        def _on_step(self) -> bool:
            if self.num_timesteps % args.eval_every < args.envs:
                measure(self.num_timesteps)
            return True

    measure(0)
    model.learn(total_timesteps=args.steps, callback=Evaluate())
    if curve[-1]["steps"] != model.num_timesteps:
        measure(model.num_timesteps)
    args.model.parent.mkdir(parents=True, exist_ok=True)
    model.save(args.model)
    venv.close()
    frame = pd.DataFrame(curve)
    for name, rate in baselines.items():
        frame[name] = rate
    frame.to_csv(args.out / "learning_curve.csv", index=False)
    draw(frame, baselines, args.out / "learning_curve.png", len(seeds))
    print(f"wrote {args.model}, {args.out}/learning_curve.csv, learning_curve.png")


def draw(frame: pd.DataFrame, baselines: dict[str, float], out: Path, episodes: int) -> None:
    """The learning curve beside the baselines."""
    from matplotlib.figure import Figure

    figure = Figure(figsize=(7, 4.2), layout="constrained")
    axes = figure.subplots()
    axes.plot(frame["steps"], frame["goals_per_min"], marker="o", label="PPO (deterministic)")
    styles = {"random": ":", "navigation (dwa)": "--"}
    for name, rate in baselines.items():
        axes.axhline(rate, linestyle=styles.get(name, "-."), color="grey", label=name)
    axes.set_xlabel("training steps (decisions of the robot)")
    axes.set_ylabel(f"goals reached per minute (mean of {episodes} episodes)")
    axes.set_title("One Jackal in the lab room learns to reach goals (PPO)")
    axes.legend(loc="lower right")
    axes.grid(alpha=0.3)
    figure.savefig(out, dpi=120)


if __name__ == "__main__":
    main()

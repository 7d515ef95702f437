"""A tour of the Python package, top to bottom (install it first: README.md, "Python").

    python examples/python_tour.py               # full sizes: a few minutes on 2 cores
    UNFORESEEN_EXAMPLE_SMALL=1 python examples/python_tour.py   # what CI runs: seconds

1. The Gymnasium env: gym.make, one episode.
2. A frame (tour-frame.png) and a video of an episode (videos/, with the `video` extra).
3. A DQN trained on the training map: with Stable-Baselines3 on the native vector env if
   it is installed (the `sb3` extra), else with skrl's JAX DQN (the `deep` extra).
4. The scaled agent around that DQN (ScaledWrapper), beside the DQN alone, on jaywalk.
5. The paper's table (unforeseen.compare) over independently trained agents (shared
   with the command line's agent cache, out/agents/), printed as the command line prints
   it, and one figure of it read from its records.
6. A search (unforeseen.search) over a space of jaywalk variations for the fair
   scenarios where Q-learning fails: the failure probability with its interval, and the
   minimised failing maps it writes (search/failures/*.ron), ready for `unforeseen batch`.

It writes into the current folder.
"""

from __future__ import annotations

import importlib.util
import os
from pathlib import Path

import gymnasium as gym
import numpy as np

import unforeseen
from unforeseen import baselines

SMALL = os.environ.get("UNFORESEEN_EXAMPLE_SMALL") == "1"
TRAIN_EPISODES = 300 if SMALL else 6000
EVAL_EPISODES = 5 if SMALL else 100
DQN_STEPS = 600 if SMALL else 20_000


def have(module: str) -> bool:
    return importlib.util.find_spec(module) is not None


# 1. The env, as any Gymnasium env.
env = gym.make("unforeseen/Jaywalk-v0")
obs, info = env.reset(seed=7)
ret, terminated, truncated = 0.0, False, False
while not (terminated or truncated):
    obs, reward, terminated, truncated, info = env.step(1)  # always speed up
    ret += reward
print(f"1. jaywalk, always speeding up: return {ret:.1f}, goal {info['goal']}, collision {info['collision']}")

# 2. A frame and a video.
env = gym.make("unforeseen/Jaywalk-v0", render_mode="rgb_array")
env.reset(seed=7)
for _ in range(6):
    env.step(1)
frame = env.render()
print(f"2. a {frame.shape[1]}x{frame.shape[0]} frame", end="")
if have("PIL"):
    from PIL import Image

    Image.fromarray(frame).save("tour-frame.png")
    print(" in tour-frame.png", end="")
if have("moviepy"):
    video = gym.wrappers.RecordVideo(env, "videos", episode_trigger=lambda ep: True, disable_logger=True)
    video.reset(seed=7)
    terminated = truncated = False
    while not (terminated or truncated):
        _, _, terminated, truncated, _ = video.step(1)
    video.close()
    print("; an episode in videos/rl-video-episode-0.mp4")
else:
    print("; no video: pip install 'unforeseen[video]'")

# 3. A DQN on the training map (kinematic observations).
if have("stable_baselines3"):
    from stable_baselines3 import DQN
    from stable_baselines3.common.vec_env import VecMonitor

    from unforeseen.sb3 import make_vec_env

    venv = VecMonitor(make_vec_env("intersection", num_envs=8, observation="kinematic"))
    model = DQN("MlpPolicy", venv, learning_starts=200, seed=1, device="cpu").learn(DQN_STEPS)

    class DQNPolicy:
        """The trained network as a policy (greedy) and a habit (softmax of its Q-values)."""

        method, observation = "sb3-dqn-kinematic", "kinematic"

        def act(self, obs):
            return int(model.predict(obs, deterministic=True)[0])

        def probs(self, obs):
            q = model.q_net(model.q_net.obs_to_tensor(obs)[0]).detach().numpy()[0]
            return np.exp(q - q.max()) / np.exp(q - q.max()).sum()

    dqn = DQNPolicy()
    print(f"3. Stable-Baselines3 DQN, {model.num_timesteps} steps on 8 native envs")
elif baselines.have_deep_extra():
    cfg = baselines.TrainConfig(
        algo="dqn", observation="kinematic", timesteps=DQN_STEPS, learning_starts=min(1000, DQN_STEPS // 4)
    )
    dqn, run = baselines.train(cfg, seed=1)
    print(f"3. skrl DQN, {run['steps']} steps, {run['episodes']} episodes")
else:
    dqn = None
    print("3. no DQN: pip install 'unforeseen[sb3]' or 'unforeseen[deep]'")

# 4. The scaled agent around the DQN: the DQN's probabilities are its habit.
agent = unforeseen.train("intersection", episodes=TRAIN_EPISODES, seed=1)
if dqn is not None:
    for policy in (dqn, unforeseen.ScaledWrapper(habit=dqn, agent=agent)):
        lines = unforeseen.evaluate(policy, ["jaywalk"], [1], episodes=EVAL_EPISODES, protocol="zero-shot")
        print(f"4. {lines[0]['method']:>24} on jaywalk: success {lines[0]['success_rate']:.0%}")

# 5. The paper's table: the methods on the test map, over independently trained agents.
agents = unforeseen.train_agents([1, 2] if SMALL else list(range(1, 11)), episodes=TRAIN_EPISODES)
report = unforeseen.compare(agents=agents, episodes=EVAL_EPISODES, protocol="zero-shot")
print(f"5. the paper's table ({len(agents)} agents, zero-shot, {report['test_map']}), as `unforeseen compare` prints it:")
print(report)  # in a notebook, report alone shows it as an HTML table
scaled = next(r for r in report.to_records() if r["method"] == "scaled")
print(f"   scaled: success {scaled['success_rate']:.0%} (95% interval {scaled['success_rate_ci95_low']:.0%}"
      f" .. {scaled['success_rate_ci95_high']:.0%} over the agents)")

# 6. A search: where does a method fail on scenarios nobody wrote by hand?
space = Path(__file__).resolve().parents[1] / "maps" / "spaces" / "jaywalk.ron"  # a space file of this repository
summary = unforeseen.search(space=space, method="q-learning", budget=8 if SMALL else 200,
                            episodes=3 if SMALL else 20, train_episodes=TRAIN_EPISODES, rounds=2 if SMALL else 5,
                            max_failures=1 if SMALL else 5, out="search")
p = summary["failure_probability"][0]["failure_probability"]
print(f"6. search: {summary['counts']['fair']} fair candidates of {summary['counts']['evaluated']}; q-learning fails in"
      f" {p['p']:.0%} of the fair Sobol points (95% interval {p['ci95_low']:.0%} .. {p['ci95_high']:.0%});"
      f" {len(summary['failures'])} minimised failure map(s) in search/failures/")

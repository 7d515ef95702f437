"""The junction maps as Gymnasium envs: registered, stepped with random actions in both
observation forms, the kinematic vector's vehicle slots (nearest first, within the
bounds), the native vector env, and the scaled wrapper around a random policy."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import unforeseen
from unforeseen import ScaledWrapper
from unforeseen.evaluate import evaluate_policy

JUNCTION = [name for name in unforeseen.embedded_maps() if name.startswith("junction_")]
#: Head, 4 pedestrian slots of 5 values, 4 vehicle slots of 6 (the defaults with traffic).
LEN = 7 + 5 * 4 + 6 * 4
VEHICLES = slice(7 + 5 * 4, LEN)


def test_every_junction_map_is_embedded_and_registered():
    assert sorted(JUNCTION) == sorted(
        f"junction_{n}"
        for n in ("training", "red_runner", "dark_signal", "stalled_box", "lead_brakes", "left_turner", "jaywalk")
    )
    assert unforeseen.env_id("junction_red_runner") == "unforeseen/JunctionRedRunner-v0"
    for name in JUNCTION:
        assert unforeseen.env_id(name) in gym.registry


def vehicle_slots(obs):
    return obs[VEHICLES].reshape(4, 6)


def test_red_runner_shows_the_runner_in_a_vehicle_slot_nearest_first():
    env = gym.make("unforeseen/JunctionRedRunner-v0", observation="kinematic")
    assert env.observation_space.shape == (LEN,)
    assert env.unwrapped._env.vehicle_slots == 4
    low, high = env.observation_space.low, env.observation_space.high
    rng = np.random.default_rng(0)
    filled = 0
    car_y = -1.75  # the car's lane centre on the shipped road (two 3.5 m lanes)
    for episode in range(4):
        obs, _ = env.reset(seed=episode)
        while True:
            assert obs.shape == (LEN,) and obs in env.observation_space, (obs, low, high)
            slots = vehicle_slots(obs)
            present = slots[:, 0] == 1.0
            assert (present == (np.arange(4) < present.sum())).all(), f"filled slots come first: {present}"
            assert (slots[~present] == 0.0).all(), "an empty slot is zeros"
            dist = np.hypot(slots[present, 1] - obs[0], slots[present, 2] - car_y)
            assert (np.diff(dist) >= -1e-3).all(), f"nearest first: {dist}"
            filled += int(present.sum())
            obs, _, terminated, truncated, _ = env.step(int(rng.integers(3)))
            if terminated or truncated:
                break
    assert filled > 0, "the red-runner appears in a vehicle slot at some tick"


def test_vehicle_slots_are_configurable_and_checked():
    assert unforeseen.make_env("junction_training", "kinematic", vehicle_slots=0).observation_space.shape == (27,)
    assert unforeseen.make_env("junction_training", "kinematic", vehicle_slots=2).observation_space.shape == (39,)
    # A map without traffic rules has no vehicle slots unless asked: its layout is unchanged.
    assert unforeseen.make_env("jaywalk", "kinematic").observation_space.shape == (27,)
    assert unforeseen.make_env("jaywalk", "kinematic", vehicle_slots=1).observation_space.shape == (33,)
    with pytest.raises(ValueError, match=r"^vehicle_slots -1: expected a whole number in 0..=100"):
        unforeseen.make_env("junction_training", "kinematic", vehicle_slots=-1)
    with pytest.raises(ValueError, match=r"^vehicle_slots 101"):
        unforeseen.VectorEnv("junction_training", 2, "kinematic", vehicle_slots=101)


@pytest.mark.parametrize("map_name", JUNCTION)
def test_junction_envs_step_with_random_actions(map_name):
    env = gym.make(unforeseen.env_id(map_name))
    rng = np.random.default_rng(1)
    obs, info = env.reset(seed=3)
    for _ in range(200):
        obs, reward, terminated, truncated, info = env.step(int(rng.integers(3)))
        assert obs in env.observation_space
        if terminated or truncated:
            obs, info = env.reset()


@pytest.mark.parametrize("observation", ["discrete", "kinematic"])
def test_the_vector_env_on_a_junction_equals_single_envs(observation):
    n, seed, steps = 3, 5, 80
    envs = gym.make_vec("unforeseen/JunctionRedRunner-v0", num_envs=n, vectorization_mode="vector_entry_point",
                        observation=observation)
    singles = [unforeseen.make_env("junction_red_runner", observation) for _ in range(n)]
    assert envs.single_observation_space == singles[0].observation_space
    actions = np.random.default_rng(2).integers(0, 3, size=(steps, n))
    vobs, _ = envs.reset(seed=seed)
    sobs = [env.reset(seed=seed + i)[0] for i, env in enumerate(singles)]
    np.testing.assert_array_equal(vobs, np.stack(sobs))
    ended = [False] * n
    for t in range(steps):
        vobs, vrew, vterm, vtrunc, _ = envs.step(actions[t])
        assert vobs in envs.observation_space
        for i, env in enumerate(singles):
            if ended[i]:
                obs, _ = env.reset()
                rew, term, trunc, ended[i] = 0.0, False, False, False
            else:
                obs, rew, term, trunc, _ = env.step(int(actions[t, i]))
                ended[i] = term or trunc
            np.testing.assert_array_equal(vobs[i], obs)
            assert (vrew[i], vterm[i], vtrunc[i]) == (rew, term, trunc)


class RandomPolicy:
    """A random kinematic policy: fresh probabilities every tick; keeps what it saw."""

    observation = "kinematic"
    method = "random"

    def __init__(self) -> None:
        self.rng = np.random.default_rng(4)
        self.seen: list[np.ndarray] = []

    def probs(self, obs):
        self.seen.append(np.array(obs))
        p = self.rng.random(3) + 0.05
        return p / p.sum()


def test_the_wrapper_drives_a_junction_around_a_random_policy(agent):
    policy = RandomPolicy()
    wrapper = ScaledWrapper(habit=policy, agent=agent)
    env = unforeseen.make_env("junction_red_runner", "kinematic")
    for episode in range(3):
        obs, info = env.reset(seed=episode)
        wrapper.begin_episode(episode)
        while True:
            action, decision = wrapper.act(obs, info)
            assert action in (0, 1, 2) and decision["action"] == action
            obs, reward, terminated, truncated, info = env.step(action)
            wrapper.observe(reward, obs, info, terminated, truncated)
            if terminated or truncated:
                break
        wrapper.end_episode()
    assert policy.seen and all(o.shape == (LEN,) for o in policy.seen)
    assert any(vehicle_slots(o)[:, 0].any() for o in policy.seen), "the policy saw the runner"
    # The library's episode loop hands the policy the same vector.
    policy.seen.clear()
    episodes = evaluate_policy(ScaledWrapper(habit=policy, agent=agent), "junction_red_runner", episodes=3)
    assert len(episodes) == 3 and all(e["ticks"] > 0 for e in episodes)
    assert policy.seen and all(o.shape == (LEN,) for o in policy.seen)

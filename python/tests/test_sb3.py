"""Stable-Baselines3 on the native vector env (unforeseen.sb3); skipped without SB3 (the
`sb3` extra brings torch, several GB: CI does not install it, BENCHMARKS.md has the run)."""

from __future__ import annotations

import numpy as np
import pytest

sb3 = pytest.importorskip("stable_baselines3", reason="Stable-Baselines3 is not installed: pip install stable-baselines3")

import unforeseen  # noqa: E402
from unforeseen.sb3 import SB3VecEnv, make_vec_env  # noqa: E402


def test_the_adapter_follows_sb3s_conventions():
    venv = make_vec_env("jaywalk", num_envs=4, observation="kinematic")
    assert venv.num_envs == 4 and venv.observation_space == venv.venv.single_observation_space
    venv.seed(5)
    obs = venv.reset()
    single = [unforeseen.make_env("jaywalk", "kinematic") for _ in range(4)]
    np.testing.assert_array_equal(obs, np.stack([env.reset(seed=5 + i)[0] for i, env in enumerate(single)]))
    ended = 0
    for _ in range(60):
        obs, rewards, dones, infos = venv.step(np.array([1, 1, 0, 2]))
        assert rewards.dtype == np.float32 and len(infos) == 4
        for i in np.flatnonzero(dones):
            ended += 1
            final = infos[i]["terminal_observation"]
            assert final.shape == obs[i].shape and not np.array_equal(final, obs[i])
            assert infos[i]["TimeLimit.truncated"] == (infos[i]["timeout"] and not infos[i]["collision"] and not infos[i]["goal"])
    assert ended > 0
    assert venv.get_attr("map_name", indices=[0, 2]) == ["jaywalk", "jaywalk"]
    assert venv.env_is_wrapped(object) == [False] * 4
    with pytest.raises(ValueError, match="SAME_STEP"):
        SB3VecEnv(unforeseen.VectorEnv("jaywalk", 2))


def test_the_adapter_runs_a_junction_map_with_vehicle_slots():
    venv = make_vec_env("junction_red_runner", num_envs=3, observation="kinematic")
    assert venv.observation_space.shape == (7 + 5 * 4 + 6 * 4,)
    venv.seed(1)
    obs = venv.reset()
    ended = 0
    for _ in range(60):
        obs, rewards, dones, infos = venv.step(np.random.default_rng(0).integers(0, 3, size=3))
        assert obs in venv.venv.observation_space
        ended += int(dones.sum())
    assert ended > 0


@pytest.mark.filterwarnings("ignore::DeprecationWarning")
@pytest.mark.filterwarnings("ignore::UserWarning")
def test_dqn_trains_on_the_native_vector_env():
    from stable_baselines3 import DQN
    from stable_baselines3.common.vec_env import VecMonitor

    venv = VecMonitor(make_vec_env("intersection", num_envs=8, observation="kinematic"))
    model = DQN("MlpPolicy", venv, learning_starts=200, seed=1, device="cpu").learn(3_000)
    assert model.num_timesteps >= 3_000
    assert len(model.ep_info_buffer) > 10  # finished episodes, counted by VecMonitor

"""Stable-Baselines3 on the native vector env: every env stepped in Rust threads.

:class:`SB3VecEnv` implements Stable-Baselines3's ``VecEnv`` interface over
:class:`unforeseen.VectorEnv` (with ``AutoresetMode.SAME_STEP``, SB3's own convention: an
env whose episode ends is reset in the same step, its final observation in
``infos[i]["terminal_observation"]`` and ``infos[i]["TimeLimit.truncated"]`` set on a
time-out)::

    from stable_baselines3 import DQN
    from stable_baselines3.common.vec_env import VecMonitor
    from unforeseen.sb3 import make_vec_env

    venv = VecMonitor(make_vec_env("intersection", num_envs=8, observation="kinematic"))
    model = DQN("MlpPolicy", venv, seed=1).learn(5_000)

Needs Stable-Baselines3 (``pip install stable-baselines3``; it brings torch). ``seed(s)``
before ``reset()`` gives env ``i`` the stream of a single env seeded ``s + i``, as SB3's
``DummyVecEnv`` does, so a run is reproducible whatever the number of threads.
"""

from __future__ import annotations

from typing import Any, Iterable, Sequence

import numpy as np
from gymnasium.vector import AutoresetMode

try:
    from stable_baselines3.common.vec_env.base_vec_env import VecEnv as _SB3VecEnv
except ImportError as e:  # pragma: no cover - depends on the environment
    raise ImportError(
        "unforeseen.sb3 needs Stable-Baselines3: pip install stable-baselines3 (it brings torch)"
    ) from e

from .vector import VectorEnv

__all__ = ["SB3VecEnv", "make_vec_env"]

#: The info entries each step passes on to SB3, per env (scalars).
_INFO_KEYS = ("goal", "collision", "timeout", "red_light")


def make_vec_env(map: str = "jaywalk", num_envs: int = 1, **kwargs: Any) -> SB3VecEnv:
    """An :class:`SB3VecEnv` over ``VectorEnv(map, num_envs, **kwargs)`` (SAME_STEP autoreset)."""
    return SB3VecEnv(VectorEnv(map, num_envs, autoreset_mode=AutoresetMode.SAME_STEP, **kwargs))


class SB3VecEnv(_SB3VecEnv):
    """Stable-Baselines3's ``VecEnv`` over a native :class:`unforeseen.VectorEnv` made with
    ``autoreset_mode=AutoresetMode.SAME_STEP``. ``infos[i]`` holds ``goal``,
    ``collision``, ``timeout`` and ``red_light`` of the step (the final step's for an env
    that ended), and for an env that ended ``terminal_observation`` and
    ``TimeLimit.truncated``."""

    def __init__(self, venv: VectorEnv) -> None:
        if venv.metadata["autoreset_mode"] != AutoresetMode.SAME_STEP:
            raise ValueError(
                "SB3VecEnv needs a VectorEnv with autoreset_mode=AutoresetMode.SAME_STEP "
                "(Stable-Baselines3's convention); unforeseen.sb3.make_vec_env makes one"
            )
        self.venv = venv
        self._actions: np.ndarray | None = None
        super().__init__(venv.num_envs, venv.single_observation_space, venv.single_action_space)

    def reset(self) -> np.ndarray:
        seeds = self._seeds
        seed = None if all(s is None for s in seeds) else [int(s) for s in seeds]
        obs, _ = self.venv.reset(seed=seed)
        self._reset_seeds()
        self._reset_options()
        self.reset_infos = [{} for _ in range(self.num_envs)]
        return obs

    def step_async(self, actions: np.ndarray) -> None:
        self._actions = actions

    def step_wait(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, list[dict[str, Any]]]:
        if self._actions is None:
            raise RuntimeError("step_wait without step_async")
        obs, rewards, terminated, truncated, info = self.venv.step(self._actions)
        self._actions = None
        dones = terminated | truncated
        # An env that ended: its final step's info (``info`` holds its reset's).
        columns = {k: np.where(dones, info["final_info"][k], info[k]).tolist() for k in _INFO_KEYS}
        infos: list[dict[str, Any]] = [{k: columns[k][i] for k in _INFO_KEYS} for i in range(self.num_envs)]
        for i in np.flatnonzero(dones):
            infos[i]["terminal_observation"] = info["final_obs"][i]
            infos[i]["TimeLimit.truncated"] = bool(truncated[i] and not terminated[i])
        return obs, rewards.astype(np.float32), dones, infos

    def close(self) -> None:
        self.venv.close()

    def get_images(self) -> Sequence[np.ndarray | None]:
        if self.render_mode != "rgb_array":
            return [None] * self.num_envs
        return list(self.venv.render() or ())

    def get_attr(self, attr_name: str, indices: Any = None) -> list[Any]:
        values = self.venv.get_attr(attr_name)
        return [values[i] for i in self._get_indices(indices)]

    def set_attr(self, attr_name: str, value: Any, indices: Any = None) -> None:
        try:
            current = list(self.venv.get_attr(attr_name))
        except AttributeError:
            current = [None] * self.num_envs
        for i in self._get_indices(indices):
            current[i] = value
        self.venv.set_attr(attr_name, current)

    def env_method(self, method_name: str, *method_args: Any, indices: Any = None, **method_kwargs: Any) -> list[Any]:
        values = self.venv.call(method_name, *method_args, **method_kwargs)
        return [values[i] for i in self._get_indices(indices)]

    def env_is_wrapped(self, wrapper_class: type, indices: Any = None) -> list[bool]:
        # The envs are Rust objects, never wrapped by Gymnasium wrappers.
        return [False for _ in self._get_indices(indices)]

    def _get_indices(self, indices: Any) -> Iterable[int]:
        if indices is None:
            return range(self.num_envs)
        if isinstance(indices, int):
            return [indices]
        return indices

"""A native vector env: every env stepped in Rust, in parallel, with the GIL released."""

from __future__ import annotations

from typing import Any, Sequence

import numpy as np
from gymnasium import spaces
from gymnasium.utils import seeding
from gymnasium.vector import AutoresetMode, VectorEnv as _GymVectorEnv
from gymnasium.vector.utils import batch_space

from . import _unforeseen
from .envs import LIGHTS, UnforeseenEnv, episode_key

__all__ = ["VectorEnv"]

_LIGHTS = np.array(LIGHTS)


class VectorEnv(_GymVectorEnv):
    """``num_envs`` copies of :class:`unforeseen.UnforeseenEnv` stepped by one Rust call.

    Spaces, rewards and flags are the single env's, batched. ``step(actions)`` steps every
    env in Rust threads (``num_threads``, default one per core) with the GIL released and
    returns numpy arrays; nothing loops over envs in Python.

    Autoreset: ``metadata["autoreset_mode"]`` is ``AutoresetMode.NEXT_STEP`` (Gymnasium
    1.x's default): the step after an env's episode ended resets that env, ignoring its
    action, and returns the reset observation with reward 0 and both flags False.

    Seeding: ``reset(seed=s)`` gives env ``i`` the episode stream of a single env after
    ``reset(seed=s + i)`` (a list of seeds gives env ``i`` ``seed[i]``), so env ``i``
    runs exactly that single env's episodes, step for step, whatever the number of
    threads. ``reset()`` without a seed draws the keys from ``self.np_random``.

    ``info`` holds arrays, one entry per env: ``step``, ``collision``, ``goal``,
    ``timeout``, ``red_light``, ``state`` and ``observed`` (``(num_envs, 4)``), ``light`` (str),
    ``light_code``, ``light_time_left``, and ``reward_terms`` (a dict of arrays), each
    with its ``_key`` mask (all True).
    """

    metadata = {"autoreset_mode": AutoresetMode.NEXT_STEP, "render_modes": []}

    def __init__(
        self,
        map: str = "jaywalk",
        num_envs: int = 1,
        observation: str = "discrete",
        render_mode: str | None = None,
        pedestrian_slots: int = 4,
        num_threads: int | None = None,
        **map_overrides: Any,
    ) -> None:
        if render_mode is not None:
            raise ValueError("VectorEnv does not render; use UnforeseenEnv for frames")
        self._env = _unforeseen.VectorEnv(map, num_envs, observation, pedestrian_slots, map_overrides, num_threads)
        single = UnforeseenEnv(map, observation, None, pedestrian_slots, **map_overrides)
        self.num_envs = num_envs
        self.render_mode = None
        self.single_observation_space = single.observation_space
        self.single_action_space = single.action_space
        self.observation_space = batch_space(self.single_observation_space, num_envs)
        self.action_space = batch_space(self.single_action_space, num_envs)
        self.metadata = {**type(self).metadata, "render_fps": single.metadata["render_fps"]}
        self._mask = np.ones(num_envs, dtype=bool)
        self.spec = None

    def reset(
        self, *, seed: int | Sequence[int] | None = None, options: dict[str, Any] | None = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        super().reset(seed=seed if isinstance(seed, int) else None)
        n = self.num_envs
        if seed is None:
            keys = [int(k) for k in self.np_random.integers(0, 2**64, size=n, dtype=np.uint64)]
        else:
            seeds = [seed + i for i in range(n)] if isinstance(seed, int) else list(seed)
            if len(seeds) != n:
                raise ValueError(f"{len(seeds)} seeds for {n} envs")
            keys = [episode_key(seeding.np_random(int(s))[0]) for s in seeds]
        obs, info = self._env.reset(keys)
        return obs, self._info(info)

    def step(self, actions: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, dict[str, Any]]:
        given = np.asarray(actions).reshape(-1)
        if given.dtype.kind not in "iu":
            whole = given.dtype.kind == "f" and bool(np.all(np.isfinite(given))) and bool(np.all(given == np.round(given)))
            if not whole:
                raise ValueError(f"actions {given!r}: expected whole numbers 0, 1 or 2, one per env")
        obs, rewards, terminated, truncated, info = self._env.step(given.astype(np.int64))
        return obs, rewards, terminated, truncated, self._info(info)

    def _info(self, info: dict[str, Any]) -> dict[str, Any]:
        info["light"] = _LIGHTS[info["light_code"]]
        for key in list(info):
            info["_" + key] = self._mask
        return info

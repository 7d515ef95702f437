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

    Autoreset: ``autoreset_mode`` (also ``metadata["autoreset_mode"]``) is
    ``AutoresetMode.NEXT_STEP`` by default (Gymnasium 1.x's default): the step after an
    env's episode ended resets that env, ignoring its action, and returns the reset
    observation with reward 0 and both flags False. With ``AutoresetMode.SAME_STEP``
    (what Stable-Baselines3 expects, :mod:`unforeseen.sb3`) the step that ends an episode
    resets the env at once: its observation is the reset one, and ``info["final_obs"]``
    and ``info["final_info"]`` (masks ``_final_obs``, ``_final_info``) hold the final
    observation and info; the other info entries are the reset's.

    Actions: integers (any integer dtype) 0, 1 or 2, one per env; floats (NaN too) are
    refused with ``TypeError``, as the single env refuses them, never truncated.

    Rendering: ``render_mode="rgb_array"``: ``render()`` returns a tuple of every env's
    frame (as Gymnasium's ``SyncVectorEnv``); ``gymnasium.wrappers.vector.HumanRendering``
    shows them tiled in a window (the ``render`` extra, pygame).

    ``get_attr(name)``, ``set_attr(name, values)`` and ``call(name, ...)`` follow
    ``SyncVectorEnv``: one value per env. The envs themselves live in Rust, so the
    attributes are those every env shares (``map_name``, ``render_mode``, ``metadata``,
    ``spec``, ``observation_space``, ``action_space``, ...), plus any attribute set with
    ``set_attr``; ``call("render")`` gives every env's frame. Setting an attribute of the env itself (a space, the
    render mode, the map) is refused: the Rust envs would not see it; make a new
    ``VectorEnv`` with that setting instead.

    Seeding: ``reset(seed=s)`` gives env ``i`` the episode stream of a single env after
    ``reset(seed=s + i)`` (a list of seeds gives env ``i`` ``seed[i]``), so env ``i``
    runs exactly that single env's episodes, step for step, whatever the number of
    threads. ``reset()`` without a seed draws the keys from ``self.np_random``.

    ``info`` holds arrays, one entry per env: ``step``, ``collision``, ``goal``,
    ``timeout``, ``red_light``, ``state`` and ``observed`` (``(num_envs, 4)``), ``light`` (str),
    ``light_code``, ``light_time_left``, and ``reward_terms`` (a dict of arrays), each
    with its ``_key`` mask (all True).
    """

    metadata = {"autoreset_mode": AutoresetMode.NEXT_STEP, "render_modes": ["rgb_array"]}

    def __init__(
        self,
        map: str = "jaywalk",
        num_envs: int = 1,
        observation: str = "discrete",
        render_mode: str | None = None,
        pedestrian_slots: int = 4,
        num_threads: int | None = None,
        autoreset_mode: AutoresetMode | str = AutoresetMode.NEXT_STEP,
        render_scale: float = 10.0,
        vehicle_slots: int | None = None,
        **map_overrides: Any,
    ) -> None:
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ValueError(
                f"render_mode {render_mode!r}: expected None or one of {self.metadata['render_modes']} "
                "(for a window: gymnasium.wrappers.vector.HumanRendering around render_mode='rgb_array')"
            )
        modes = {AutoresetMode.NEXT_STEP: "next_step", AutoresetMode.SAME_STEP: "same_step"}
        mode = AutoresetMode(autoreset_mode)
        if mode not in modes:
            raise ValueError(f"autoreset_mode {mode}: expected AutoresetMode.NEXT_STEP or AutoresetMode.SAME_STEP")
        self._env = _unforeseen.VectorEnv(
            map, num_envs, observation, pedestrian_slots, map_overrides, num_threads, modes[mode], vehicle_slots
        )
        single = UnforeseenEnv(
            map, observation, render_mode, pedestrian_slots, render_scale, vehicle_slots, **map_overrides
        )
        self._single = single
        self.num_envs = num_envs = self._env.num_envs
        self.render_mode = render_mode
        self._scale = float(render_scale)
        self.single_observation_space = single.observation_space
        self.single_action_space = single.action_space
        self.observation_space = batch_space(self.single_observation_space, num_envs)
        self.action_space = batch_space(self.single_action_space, num_envs)
        self.metadata = {**type(self).metadata, "render_fps": single.metadata["render_fps"], "autoreset_mode": mode}
        self._mask = np.ones(num_envs, dtype=bool)
        self._attrs: list[dict[str, Any]] = [{} for _ in range(num_envs)]
        self.spec = None

    def reset(
        self, *, seed: int | Sequence[int] | None = None, options: dict[str, Any] | None = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        n = self.num_envs
        seeds: list[int] | None = None
        if seed is None:
            super().reset(seed=None)
        elif isinstance(seed, (str, bytes)) or not hasattr(seed, "__iter__"):
            try:
                one = _unforeseen.argument("seed", "seed", seed)
            except ValueError:
                raise ValueError(f"seed {seed!r}: expected an int, a sequence of {n} ints or None") from None
            super().reset(seed=one)
            seeds = [one + i for i in range(n)]
        else:
            seeds = [_unforeseen.argument(f"seed[{i}]", "seed", s) for i, s in enumerate(seed)]
            if len(seeds) != n:
                raise ValueError(f"seed: {len(seeds)} seeds for {n} envs; give one per env, or one int")
            super().reset(seed=None)
        if seeds is None:
            keys = [int(k) for k in self.np_random.integers(0, 2**64, size=n, dtype=np.uint64)]
        else:
            keys = [episode_key(seeding.np_random(s)[0]) for s in seeds]
        obs, info = self._env.reset(keys)
        return obs, self._info(info)

    def step(self, actions: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, dict[str, Any]]:
        obs, rewards, terminated, truncated, info = self._env.step(_int_actions(actions))
        final_obs = info.pop("final_obs", None)
        final_info = info.pop("final_info", None)
        info = self._info(info)
        if final_obs is not None:
            ended = terminated | truncated
            arr = np.empty(self.num_envs, dtype=object)
            arr[:] = final_obs
            info["final_obs"], info["_final_obs"] = arr, ended
            info["final_info"], info["_final_info"] = self._info(final_info, ended), ended
        return obs, rewards, terminated, truncated, info

    def render(self) -> tuple[np.ndarray, ...] | None:
        """Every env's frame (``render_mode="rgb_array"``), as ``SyncVectorEnv`` gives them."""
        if self.render_mode is None:
            return None
        return tuple(self._env.render_rgb(self._scale))

    def get_attr(self, name: str) -> tuple[Any, ...]:
        """The attribute ``name`` of every env (see the class docs for which exist)."""
        return tuple(self._attr(i, name) for i in range(self.num_envs))

    def set_attr(self, name: str, values: Any) -> None:
        """Sets ``name`` on every env: ``values`` one per env (a list or tuple), or one
        value for all. Attributes of the env itself are refused (see the class docs)."""
        if hasattr(self._single, name):
            raise AttributeError(
                f"set_attr({name!r}): {name!r} is a setting of the envs, which run in Rust and would "
                "not see a new value; make a new VectorEnv with it instead"
            )
        if not isinstance(values, (list, tuple)):
            values = [values] * self.num_envs
        if len(values) != self.num_envs:
            raise ValueError(f"set_attr({name!r}): {len(values)} values for {self.num_envs} envs")
        for attrs, value in zip(self._attrs, values):
            attrs[name] = value

    def call(self, name: str, *args: Any, **kwargs: Any) -> tuple[Any, ...]:
        """Calls the method ``name`` of every env (``render``, or a callable set with
        ``set_attr``) or, for an attribute that is not callable, gets it."""
        if name == "render":
            return tuple(self._env.render_rgb(self._scale))
        out = []
        for i in range(self.num_envs):
            value = self._attr(i, name)
            if callable(value):
                if name not in self._attrs[i]:
                    raise AttributeError(
                        f"call({name!r}): the envs run in Rust and are stepped together; "
                        "use the vector env's own methods (reset, step, render)"
                    )
                value = value(*args, **kwargs)
            out.append(value)
        return tuple(out)

    def _attr(self, i: int, name: str) -> Any:
        if name in self._attrs[i]:
            return self._attrs[i][name]
        if name.startswith("_") or not hasattr(self._single, name):
            raise AttributeError(f"the envs have no attribute {name!r}")
        return getattr(self._single, name)

    def _info(self, info: dict[str, Any], mask: np.ndarray | None = None) -> dict[str, Any]:
        mask = self._mask if mask is None else mask
        info["light"] = _LIGHTS[info["light_code"]]
        for key in list(info):
            info["_" + key] = mask
        return info


def _int_actions(actions: Any) -> np.ndarray:
    """``actions`` as int64, one per env; anything but integers is refused (a float
    action would otherwise be truncated: ``1.7`` to ``1``)."""
    a = np.asarray(actions)
    if a.dtype.kind not in "iu":
        raise TypeError(
            f"actions must be integers 0, 1 or 2 (one per env), got dtype {a.dtype}: "
            f"{np.array2string(a.reshape(-1)[:8], separator=', ')}; round or cast them explicitly"
        )
    if a.dtype.kind == "u" and a.size and a.max() > np.iinfo(np.int64).max:
        raise ValueError(f"action {a.max()} is not one of 0 (maintain), 1 (speed up), 2 (slow down)")
    return a.astype(np.int64, copy=False).reshape(-1)

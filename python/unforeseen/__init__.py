"""unforeseen: the intersection of *Active Inference as the Test-Time Scaling Law for
Physical AI Agents* (a Rapier 2D world in Rust) as Gymnasium environments, with the
paper's agents.

Importing registers one Gymnasium id per embedded map (``unforeseen/Jaywalk-v0``,
``unforeseen/Intersection-v0``, ...), each with a native vector entry point::

    import gymnasium as gym, unforeseen
    env = gym.make("unforeseen/Jaywalk-v0")
    envs = gym.make_vec("unforeseen/Jaywalk-v0", num_envs=64, vectorization_mode="vector_entry_point")

Every number comes from the Rust crates the ``unforeseen`` command line uses.
"""

from __future__ import annotations

from typing import Any, Mapping, Sequence

import gymnasium as gym

from . import _unforeseen
from ._unforeseen import (
    Agent,
    BatchResult,
    CompareResult,
    Controller,
    EvalResult,
    embedded_maps,
    load_agent,
    scripted_controller,
    stream_seed,
    train_agents,
)
from .envs import ACTIONS, LIGHTS, UnforeseenEnv
from .evaluate import EvaluateResult, evaluate, evaluate_policy, summarize
from .search import search
from .vector import VectorEnv
from .wrapper import ScaledWrapper, q_table_habit

__version__ = _unforeseen.version()

__all__ = [
    "ACTIONS",
    "LIGHTS",
    "Agent",
    "BatchResult",
    "CompareResult",
    "Controller",
    "EvalResult",
    "EvaluateResult",
    "ScaledWrapper",
    "UnforeseenEnv",
    "VectorEnv",
    "batch",
    "compare",
    "embedded_maps",
    "env_id",
    "eval_seeds",
    "evaluate",
    "evaluate_builtin",
    "evaluate_policy",
    "load_agent",
    "make_env",
    "q_table_habit",
    "rollout",
    "scripted_controller",
    "search",
    "stream_seed",
    "summarize",
    "train",
    "train_agents",
]


def env_id(map_name: str) -> str:
    """The Gymnasium id of an embedded map: ``jaywalk_late`` -> ``unforeseen/JaywalkLate-v0``."""
    return "unforeseen/" + "".join(part.capitalize() for part in map_name.split("_")) + "-v0"


def _register() -> None:
    for name in embedded_maps():
        id_ = env_id(name)
        if id_ not in gym.registry:
            gym.register(
                id=id_,
                entry_point="unforeseen.envs:UnforeseenEnv",
                vector_entry_point="unforeseen.vector:VectorEnv",
                kwargs={"map": name},
            )


_register()


def make_env(
    map: str = "jaywalk",
    observation: str = "discrete",
    render_mode: str | None = None,
    **map_overrides: Any,
) -> UnforeseenEnv:
    """An env of ``map`` (embedded name or map file); keywords override map fields
    (``max_steps=60``), checked by the map loader (a bad one raises ``ValueError``
    with the loader's diagnostic)."""
    return UnforeseenEnv(map, observation, render_mode, **map_overrides)


def train(map: str = "intersection", episodes: int = 6000, seed: int = 7) -> Agent:
    """Trains Q-learning, the world model and Bayesian RL on ``map`` (``unforeseen train``)."""
    return _unforeseen.train(map, episodes, seed)


def eval_seeds(seed: int, map: str, method: str, episode: int) -> tuple[int, int]:
    """``(world, controller)`` seeds of evaluation episode ``episode`` of the method named
    ``method`` on ``map`` (as ``unforeseen eval`` uses them): the world seed depends on
    ``seed``, the map and the episode only; the controller seed on the name too (a
    built-in method's, or the name a Python policy's lines carry, :func:`evaluate`)."""
    return _unforeseen.eval_seeds(seed, map, method, episode)


def evaluate_builtin(
    map: str,
    method: str = "scaled",
    episodes: int = 100,
    seed: int = 7,
    agent: Agent | None = None,
    protocol: str = "zero-shot",
    **params: Any,
) -> EvalResult:
    """``unforeseen eval`` run by the Rust library. Returns an :class:`EvalResult`:
    ``print(result)`` gives the line ``eval`` prints, ``result["aggregate"]`` and
    ``result["episodes"]`` (or ``to_dict()``) eval.json's data, and ``to_pandas()`` one
    row per episode. ``params`` are the ``--set`` keys."""
    return _unforeseen.evaluate_report(map, method, episodes, seed, agent, protocol, **params)


def rollout(
    map: str,
    method: str = "scaled",
    episodes: int = 100,
    seed: int = 7,
    agent: Agent | None = None,
    protocol: str = "zero-shot",
    **params: Any,
) -> list[dict[str, Any]]:
    """The episodes of :func:`evaluate_builtin` (the library's evaluation, as ``unforeseen
    eval`` runs it) without the fields that measure time: per episode ``ret``,
    ``success``, ``collision``, ``timeout``, ``ticks``, ``reasoning_ticks`` and
    ``jaywalk_surprise``. To evaluate a Python policy, see :func:`evaluate`."""
    report = evaluate_builtin(map, method, episodes, seed, agent, protocol, **params)
    keys = ("ret", "success", "collision", "timeout", "ticks", "reasoning_ticks", "jaywalk_surprise")
    return [{k: e[k] for k in keys} for e in report["episodes"]]


def compare(
    agents: Agent | Sequence[Agent],
    train_map: str = "intersection",
    test_map: str = "jaywalk",
    episodes: int = 100,
    seed: int = 7,
    protocols: Sequence[str] = ("zero-shot", "continual"),
    ablations: bool = False,
    **params: Any,
) -> CompareResult:
    """``unforeseen compare`` in the library: the paper's table (§VI) of ``agents`` (one
    agent, or several from :func:`train_agents`, summarized over them), trained on
    ``train_map`` and tested on ``test_map``, one table per protocol. Returns a
    :class:`CompareResult`: ``print(result)`` gives the tables ``compare`` prints,
    ``result["tables"]`` (or ``to_dict()``) compare.json's data, and ``to_pandas()`` one
    row per (protocol, method). ``params`` are the ``--set`` keys."""
    return _unforeseen.compare_report(agents, train_map, test_map, episodes, seed, list(protocols), ablations,
                                      **params)


def batch(
    *maps: str,
    agents: Agent | Sequence[Agent],
    episodes: int = 100,
    seed: int = 7,
    methods: Sequence[str] | None = None,
    protocols: Sequence[str] = ("zero-shot", "continual"),
    sweep: Mapping[str, Any] | None = None,
    jobs: int = 2,
) -> BatchResult:
    """``unforeseen batch`` in the library: every (map, method, parameter set, protocol,
    agent) as one unit (no maps: the embedded ones; ``methods`` default to the paper's
    three and the scripted references; ``sweep`` maps a ``--set`` key to a value or a
    list of values, their cross product). Returns a :class:`BatchResult`:
    ``print(result)`` gives the summary table ``batch`` prints, ``result["lines"]`` the
    results file's lines and ``result["summary"]`` the summary's rows, and
    ``to_pandas()`` one row per summary row."""
    return _unforeseen.batch_report(list(maps), agents, episodes, seed, None if methods is None else list(methods),
                                    list(protocols), None if sweep is None else dict(sweep), jobs)

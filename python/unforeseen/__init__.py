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

import os
from collections.abc import Iterable, Sequence
from typing import Any

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
)
from .envs import ACTIONS, LIGHTS, UnforeseenEnv
from .estimate import estimate
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
    "estimate",
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


def train(map: str | os.PathLike[str] = "intersection", episodes: int = 6000, seed: int = 7) -> Agent:
    """Trains Q-learning, the world model and Bayesian RL on ``map`` (an embedded name or
    a map file) for ``episodes`` episodes from ``seed`` (``unforeseen train``); Ctrl-C
    raises ``KeyboardInterrupt``."""
    return _unforeseen.train(map, episodes, seed)


def train_agents(
    seeds: Iterable[int],
    map: str | os.PathLike[str] = "intersection",
    episodes: int = 6000,
    cache: str | os.PathLike[str] | None = None,
    timeout_as: str = "truncation",
) -> list[Agent]:
    """Trains one agent per seed of ``seeds`` (at most 1,000, each once, as
    ``--train-seeds`` takes them) on ``map`` for ``episodes`` episodes, in parallel, as
    ``unforeseen compare --train-seeds`` does. With ``cache`` (a folder, e.g.
    ``"out/agents"``, the command line's) agents are loaded from it when there and saved
    into it, so a notebook and the command line share them; without it (the default)
    nothing is written. Ctrl-C raises ``KeyboardInterrupt``."""
    return _unforeseen.train_agents(seeds, map, episodes, cache, timeout_as)


def eval_seeds(seed: int, map: str, method: str, episode: int) -> tuple[int, int]:
    """``(world, controller)`` seeds of evaluation episode ``episode`` of the method named
    ``method`` on ``map`` (as ``unforeseen eval`` uses them): the world seed depends on
    ``seed``, the map and the episode only; the controller seed on the name too (a
    built-in method's, or the name a Python policy's lines carry, :func:`evaluate`)."""
    return _unforeseen.eval_seeds(seed, map, method, episode)


def evaluate_builtin(
    map: str = "jaywalk",
    method: str = "scaled",
    *,
    stream: str | os.PathLike[str] | None = None,
    episodes: int = 100,
    protocol: str = "zero-shot",
    sets: Sequence[str] = (),
    seed: int = 7,
    out: str | os.PathLike[str] | None = "out/eval",
    agent: str | os.PathLike[str] | Agent | None = None,
    force: bool = False,
) -> EvalResult:
    """``unforeseen eval`` in this process: the same request, planned and run by the
    library as the command line runs it, writing the same ``eval.json`` into ``out``
    (None: no file). ``method`` runs on ``map`` (or over the maps of the deployment
    ``stream`` file) for ``episodes`` episodes from ``seed`` under ``protocol``
    (``"zero-shot"`` or ``"continual"``), with the scaled agent's overrides ``sets``
    (``"KEY=VALUE"`` each, the ``--set`` keys). ``agent`` is an agent file or an
    :class:`Agent`; without one, a method that needs an agent trains one on
    ``intersection`` with ``seed`` (scripted references need none). A bad argument
    raises ``ValueError`` naming it, and so does a file in ``out`` that is not an
    earlier ``eval.json`` (unless ``force``). Returns an :class:`EvalResult`: ``print(result)``
    gives the line ``eval`` prints, ``result["aggregate"]`` and ``result["episodes"]``
    (or ``to_dict()``) eval.json's data, and ``to_pandas()`` one row per episode."""
    fields = dict(locals())
    given = fields.pop("agent") if isinstance(agent, Agent) else None
    return _unforeseen.evaluate(fields, given)


def rollout(
    map: str = "jaywalk",
    method: str = "scaled",
    *,
    episodes: int = 100,
    protocol: str = "zero-shot",
    sets: Sequence[str] = (),
    seed: int = 7,
    agent: str | os.PathLike[str] | Agent | None = None,
) -> list[dict[str, Any]]:
    """The episodes of :func:`evaluate_builtin` (the library's evaluation, as ``unforeseen
    eval`` runs it; no file written) without the fields that measure time: per episode
    ``ret``, ``success``, ``collision``, ``timeout``, ``ticks``, ``reasoning_ticks`` and
    ``jaywalk_surprise``. To evaluate a Python policy, see :func:`evaluate`."""
    report = evaluate_builtin(map, method, episodes=episodes, protocol=protocol, sets=sets, seed=seed, out=None,
                              agent=agent)
    keys = ("ret", "success", "collision", "timeout", "ticks", "reasoning_ticks", "jaywalk_surprise")
    return [{k: e[k] for k in keys} for e in report["episodes"]]


def compare(
    agents: Agent | Sequence[Agent] | None = None,
    *,
    train_map: str = "intersection",
    test_map: str = "jaywalk",
    train_episodes: int = 6000,
    episodes: int = 100,
    ablations: bool = False,
    protocol: str = "both",
    sets: Sequence[str] = (),
    seed: int = 7,
    out: str | os.PathLike[str] | None = "out/compare",
    agent: str | os.PathLike[str] | None = None,
    train_seeds: Iterable[int] | str | None = None,
    timeout_as: str = "truncation",
    cache: str | os.PathLike[str] | None = None,
    force: bool = False,
) -> CompareResult:
    """``unforeseen compare`` in this process: the paper's table (§VI), the same request
    planned, trained and run by the library as the command line runs it, writing the
    same compare.json, compare.csv, compare_seeds.csv and compare.svg into ``out``
    (None: no files). The agents: ``agents`` (an :class:`Agent`, or several from
    :func:`train_agents`, summarized over them), ``agent`` (an agent file),
    ``train_seeds`` (one agent per seed, ``range(1, 5)`` or ``"1..4"``, trained on
    ``train_map`` for ``train_episodes``, and kept in the agent cache ``cache`` when one
    is given: e.g. ``"out/agents"``, the command line's), or none of them (one agent trained with ``seed``). They are tested on
    ``test_map`` for ``episodes`` episodes per method under ``protocol``
    (``"zero-shot"``, ``"continual"`` or ``"both"``), with the ablations when
    ``ablations``, and the scaled agent's overrides ``sets`` (``"KEY=VALUE"`` each). A
    bad argument raises ``ValueError`` naming it, and so does a file in ``out`` that is
    not one of an earlier comparison's (unless ``force``). Returns a :class:`CompareResult`:
    ``print(result)`` gives the tables ``compare`` prints, ``result["tables"]`` (or
    ``to_dict()``) compare.json's data, and ``to_pandas()`` one row per (protocol,
    method)."""
    fields = dict(locals())
    given = fields.pop("agents")
    return _unforeseen.compare(fields, given)


def batch(
    maps: str | os.PathLike[str] | Sequence[str | os.PathLike[str]] = (),
    *,
    stream: str | os.PathLike[str] | None = None,
    methods: Sequence[str] = (),
    protocol: str = "both",
    sets: Sequence[str] = (),
    episodes: int = 100,
    seed: int = 7,
    jobs: int | None = None,
    out: str | os.PathLike[str] = "results.jsonl",
    resume: bool = False,
    force: bool = False,
    shard: str | None = None,
    agent: str | os.PathLike[str] | Agent | None = None,
    train_seeds: Iterable[int] | str | None = None,
    train_map: str = "intersection",
    train_episodes: int = 6000,
    timeout_as: str = "truncation",
    cache: str | os.PathLike[str] | None = None,
) -> BatchResult:
    """``unforeseen batch`` in this process: the same request, planned, trained and run by
    the library as the command line runs it, writing the same results file ``out`` and
    the summary beside it (``results.summary.json``). :func:`unforeseen.distributed.run_batch`
    takes the same arguments and runs the units on a Ray cluster.

    Every (map, method, parameter set, protocol, training seed) is one unit:

    * ``maps``: map files, folders of maps or embedded names (none: the embedded maps);
      or ``stream``, a deployment stream file, as the one scenario;
    * ``methods``: method names (none: q-learning, bayes-rl, scaled, brake-on-pedestrian
      and never-brake); ``protocol``: ``"zero-shot"``, ``"continual"`` or ``"both"``;
    * ``sets``: the sweep, one ``"KEY=V1,V2"`` per parameter (the cross product);
    * the agents: ``agent`` (an agent file, or an :class:`Agent`), ``train_seeds`` (one
      agent per seed, ``range(1, 5)`` or ``"1..4"``, trained on ``train_map`` for
      ``train_episodes``, and kept in the agent cache ``cache`` when one is given: e.g.
      ``"out/agents"``, the command line's), or
      neither (one agent trained with ``seed``; scripted methods alone need none);
    * ``episodes`` per unit, the evaluation ``seed``, ``jobs`` threads (None: every
      core), ``resume`` (keep the lines of the same run in ``out``), ``force`` (replace an
      ``out`` that is not a results file), ``shard`` (``"I/N"``: one slice of the units).

    A bad argument raises ``ValueError`` naming it (``train_seeds: ...``) before any work.
    Returns a :class:`BatchResult`: ``print(result)`` gives the summary table ``batch``
    prints, ``result["lines"]`` the results file's lines and ``result["summary"]`` the
    summary's rows, and ``to_pandas()`` one row per summary row."""
    fields = dict(locals())
    given = fields.pop("agent") if isinstance(agent, Agent) else None
    return _unforeseen.batch(fields, given)

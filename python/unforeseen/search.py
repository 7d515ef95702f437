"""``unforeseen search`` in this process: the search for the fair scenarios where a method
fails (README, "Searching for the unforeseen"), with the arguments of
:func:`unforeseen.distributed.run_search` and the same folder of outputs
(``candidates.jsonl``, ``summary.json``, ``failures/*.ron``, ``search.svg``), timing
fields aside, as the command line writes them. The stages run in the library
(``unforeseen_harness::runs::search``); the candidates run on ``jobs`` threads."""

from __future__ import annotations

import json
import os
import threading
from collections.abc import Iterable
from typing import Any, NamedTuple

from . import _unforeseen


class SearchPlan(NamedTuple):
    """A checked search request: what :func:`search` and
    :func:`unforeseen.distributed.run_search` both run."""

    spec: str
    """The request as the binding reads it (JSON text)."""
    from_file: bool
    """Whether the agent is one file (``agent``) rather than trained per seed."""
    train: list[int]
    """The training seeds of the agents to train (empty for a scripted method or a file)."""


def plan_search(
    *,
    space: str | os.PathLike[str],
    map: str | os.PathLike[str],
    method: str,
    protocol: str,
    budget: int,
    episodes: int,
    seed: int,
    sobol_share: float,
    rounds: int,
    max_failures: int,
    train_seeds: Iterable[int] | None,
    train_episodes: int,
    agent: str | os.PathLike[str] | None,
) -> SearchPlan:
    """Checks a search request (arguments, map, space) with the binding's checks, before
    any work, and says which agents it needs: a file (``agent``), one per training seed,
    or, with neither, one trained with ``seed``. ``ValueError`` names what is wrong."""
    seeds = None if train_seeds is None else list(train_seeds)
    if seeds is not None and agent is not None:
        raise ValueError("train_seeds and agent: give one (train agents per seed, or search with one agent file)")
    spec = json.dumps(
        {
            "map": str(map),
            "space": str(space),
            "method": method,
            "protocol": protocol,
            "budget": budget,
            "episodes": episodes,
            "seed": seed,
            "sobol_share": sobol_share,
            "rounds": rounds,
            "max_failures": max_failures,
            "train_seeds": seeds,
            "train_episodes": train_episodes,
        }
    )
    scripted = _unforeseen.check_search(spec)
    from_file = agent is not None and not scripted
    train = [] if scripted or from_file else (seeds if seeds is not None else [seed])
    return SearchPlan(spec, from_file, train)


def search(
    *,
    space: str | os.PathLike[str],
    map: str | os.PathLike[str] = "jaywalk",
    method: str = "scaled",
    protocol: str = "zero-shot",
    budget: int = 100,
    episodes: int = 20,
    seed: int = 7,
    sobol_share: float = 0.5,
    rounds: int = 5,
    max_failures: int = 5,
    out: str | os.PathLike[str] = "out/search",
    train_seeds: Iterable[int] | None = None,
    train_episodes: int = 6000,
    agent: str | os.PathLike[str] | None = None,
    resume: bool = False,
    jobs: int = 1,
    command: str | None = None,
) -> dict[str, Any]:
    """Searches ``space`` (a space file over the base ``map``) for the fair scenarios where
    ``method`` fails, as ``unforeseen search`` does: scrambled Sobol points, then adaptive
    rounds, then each failure minimised toward the base. Agents: one file (``agent``), one
    per training seed (``train_seeds``, trained on the intersection for
    ``train_episodes``), or, with neither, one trained with ``seed``. Writes the folder
    ``out`` and returns ``summary.json``'s contents. ``ValueError`` names a bad argument,
    map or space before any work; Ctrl-C raises ``KeyboardInterrupt``."""
    if not 1 <= jobs <= 256:
        raise ValueError(f"jobs={jobs}: expected 1 to 256 worker threads")
    plan = plan_search(
        space=space, map=map, method=method, protocol=protocol, budget=budget, episodes=episodes, seed=seed,
        sobol_share=sobol_share, rounds=rounds, max_failures=max_failures, train_seeds=train_seeds,
        train_episodes=train_episodes, agent=agent,
    )
    spec, from_file = plan.spec, plan.from_file
    agents: list[tuple[int | None, bytes]]
    if from_file:
        agents = [(None, _unforeseen.search_agent_text(str(agent)))]
    else:
        agents = [(s, _unforeseen.train_agent(s, train_episodes)) for s in plan.train]
    # Set by the binding on Ctrl-C: `evaluate` runs on the driver's other threads.
    stop = threading.Event()

    def evaluate(candidates: list[str]) -> list[list[str]]:
        if stop.is_set():
            raise KeyboardInterrupt
        return _unforeseen.evaluate_search_candidates(spec, agents, candidates, from_file, jobs)

    summary = _unforeseen.drive_search(
        spec,
        agents,
        evaluate,
        str(out),
        resume=resume,
        from_file=from_file,
        jobs=max(1, max_failures),
        command=command if command is not None else f"unforeseen.search(space={str(space)!r}, ...)",
        stop=stop,
    )
    return json.loads(summary)

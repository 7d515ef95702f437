"""Python policies as methods in the tables: :func:`evaluate` runs any policy on the
maps with the evaluation episodes of ``unforeseen eval`` / ``unforeseen batch`` (the
same world seeds: every method meets the same pedestrians) and writes lines of the
batch results schema (``unforeseen::batch::ResultLine``), which the batch summary
(:func:`summarize`) and ``unforeseen plot-sweep`` read beside the built-in methods.

A policy is any object with ``act(obs, info)`` returning an action or
``(action, decision)`` (a decision dict with ``reasoned``, as :class:`unforeseen.Controller`
gives); optional: ``observation`` (``"discrete"`` or ``"kinematic"``, the env form it
reads), ``method`` (its name in the lines), ``learns`` (whether it learns across
episodes), ``begin_episode(seed)``, ``observe(reward, obs, info, terminated, truncated)``,
``end_episode()`` and ``reset_learning()`` (called before every zero-shot episode).
"""

from __future__ import annotations

import json
import os
import time
from typing import Any, Callable, Iterable, Mapping

from . import _unforeseen
from .envs import UnforeseenEnv

__all__ = ["EvaluateResult", "evaluate", "evaluate_policy", "summarize", "PROTOCOLS"]

PROTOCOLS = ("zero-shot", "continual")


def _source(map: str) -> tuple[str, str]:
    """``(scenario name, source)`` as the batch writes them."""
    env = _unforeseen.Env(map)
    name = env.map_name
    if os.path.exists(map):
        return name, str(map)
    return name, f"embedded:{map}"


def _efe_tree(params: Mapping[str, Any]) -> int:
    """U + U^2 + ... + U^H, the prefix-tree size of a plan (3 actions)."""
    h = int(params.get("horizon", 3))
    return sum(3**k for k in range(1, h + 1))


def evaluate_policy(
    policy: Any,
    map: str,
    episodes: int = 100,
    protocol: str = "zero-shot",
    seed: int = 7,
) -> list[dict[str, Any]]:
    """Runs ``policy`` for ``episodes`` evaluation episodes of ``map`` under
    ``protocol``: per episode ``ret``, ``success``, ``collision``, ``timeout``,
    ``red_lights``, ``ticks``, ``reasoning_ticks`` and ``decide_s`` (seconds inside the
    policy)."""
    if protocol not in PROTOCOLS:
        raise ValueError(f"protocol {protocol!r}: expected one of {PROTOCOLS}")
    if episodes < 1:
        raise ValueError(f"episodes {episodes}: expected at least 1")
    env = UnforeseenEnv(map, getattr(policy, "observation", "discrete"))
    out = []
    for ep in range(episodes):
        # The world seed depends on the map and episode only; the controller seed is the
        # scaled agent's (so a wrapper around the Q-table is the built-in agent).
        world, ctrl = _unforeseen.eval_seeds(seed, map, "scaled", ep)
        if protocol == "zero-shot" and hasattr(policy, "reset_learning"):
            policy.reset_learning()
        obs, info = env.reset(options={"world_seed": world})
        if hasattr(policy, "begin_episode"):
            policy.begin_episode(ctrl)
        r = {"ret": 0.0, "success": False, "collision": False, "timeout": False, "red_lights": 0,
             "ticks": 0, "reasoning_ticks": 0, "decide_s": 0.0}
        while True:
            t0 = time.perf_counter()
            decided = policy.act(obs, info)
            r["decide_s"] += time.perf_counter() - t0
            if isinstance(decided, tuple):
                action, decision = decided
                r["reasoning_ticks"] += bool(decision.get("reasoned", False))
            else:
                action = decided
            obs, reward, terminated, truncated, info = env.step(int(action))
            r["ret"] += float(reward)
            r["ticks"] += 1
            r["red_lights"] += bool(info["red_light"])
            if hasattr(policy, "observe"):
                policy.observe(reward, obs, info, terminated, truncated)
            if terminated or truncated:
                r["collision"] = bool(info["collision"])
                r["success"] = bool(info["goal"]) and not r["collision"]
                r["timeout"] = bool(info["timeout"])
                break
        if hasattr(policy, "end_episode"):
            policy.end_episode()
        out.append(r)
    return out


def _line(
    unit: int,
    map: str,
    method: str,
    protocol: str,
    covers: list[str],
    train_seed: int | None,
    train_episodes: int | None,
    seed: int,
    results: list[dict[str, Any]],
    matvecs_per_reasoning_tick: int,
) -> dict[str, Any]:
    scenario, source = _source(map)
    n = len(results)
    ticks = sum(r["ticks"] for r in results)
    reasoning = sum(r["reasoning_ticks"] for r in results)
    inference = reasoning / ticks if ticks else 0.0
    return {
        "unit": unit,
        "scenario": scenario,
        "source": source,
        "method": method,
        "param_set": "default",
        "params": [],
        "protocol": protocol,
        "covers": covers,
        "train_seed": train_seed,
        "train_episodes": train_episodes,
        "seed": seed,
        "episodes": n,
        "mean_reward": sum(r["ret"] for r in results) / n,
        "success_rate": sum(r["success"] for r in results) / n,
        "collision_rate": sum(r["collision"] for r in results) / n,
        "timeout_rate": sum(r["timeout"] for r in results) / n,
        "red_light_rate": sum(r["red_lights"] for r in results) / n,
        "inference_rate": inference,
        "efe_matvecs_per_tick": inference * matvecs_per_reasoning_tick,
        "mean_ticks": ticks / n,
        "checks": [],
        "timing_us_per_tick": (sum(r["decide_s"] for r in results) / ticks * 1e6) if ticks else 0.0,
    }


class EvaluateResult(list):
    """The result lines :func:`evaluate` returns: a list of dicts, one per unit, as
    before, that also prints as the summary table ``unforeseen batch`` prints for these
    lines (summarized and rendered by the Rust code of the command line: ``str()``,
    ``_repr_markdown_`` and ``_repr_html_``); :attr:`report` is that
    :class:`~unforeseen.BatchResult` (``report.summary``: the summary's rows) and
    :meth:`to_pandas` its rows as a DataFrame."""

    @property
    def report(self) -> _unforeseen.BatchResult:
        """The batch report of these lines: ``lines`` and the ``summary`` over training seeds."""
        return _unforeseen.batch_result(json.dumps(list(self)))

    def __str__(self) -> str:
        return str(self.report)

    def _repr_markdown_(self) -> str:
        return self.report._repr_markdown_()

    def _repr_html_(self) -> str:
        return self.report._repr_html_()

    def to_pandas(self) -> Any:
        """The summary's rows as a pandas DataFrame (``ImportError`` naming the ``pandas``
        extra where pandas is not installed)."""
        return self.report.to_pandas()


def evaluate(
    policy: Any,
    maps: Iterable[str],
    seeds: Iterable[int | None],
    episodes: int = 100,
    protocol: str | Iterable[str] = ("zero-shot", "continual"),
    out: str | os.PathLike[str] | None = None,
    method: str | None = None,
    seed: int = 7,
    train_episodes: int | None = None,
    force: bool = False,
) -> EvaluateResult:
    """Evaluates a policy per training seed on every map under every protocol and
    returns the batch result lines (dicts, in an :class:`EvaluateResult`: ``print()`` it
    for the summary table ``unforeseen batch`` prints); with ``out``, appends them to that JSON Lines
    file (one line per unit as it finishes), beside the lines of other methods. ``out``
    is checked first as ``unforeseen batch --out`` is: a ``ValueError`` if it is one of
    the map files, if it holds something other than batch results (unless ``force``:
    then it is replaced), if it already holds a line of the same map, method, protocol
    and training seed (a second call would count it twice), or if another run is writing
    it.

    ``policy``: a policy, a mapping ``train_seed -> policy`` or a callable
    ``train_seed -> policy`` (the policy trained with that seed). ``seeds``: the training
    seeds (``None`` for a policy without one). ``protocol``: ``"zero-shot"``,
    ``"continual"`` or both; a policy whose ``learns`` is false runs once and its line
    covers every protocol asked (as the batch does for methods that do not learn).
    ``method``: the name in the lines (default: the policy's ``method`` attribute).
    ``seed``: the evaluation seed (the batch's ``--seed``)."""
    protocols = [protocol] if isinstance(protocol, str) else list(protocol)
    for p in protocols:
        if p not in PROTOCOLS:
            raise ValueError(f"protocol {p!r}: expected one of {PROTOCOLS}")
    maps = list(maps)
    seeds = list(seeds)
    if not maps or not seeds or not protocols:
        raise ValueError("evaluate: give at least one map, one training seed and one protocol")

    def policy_of(s: int | None) -> Any:
        if isinstance(policy, Mapping):
            return policy[s]
        if callable(policy) and not hasattr(policy, "act"):
            return policy(s)
        return policy

    lines = []
    unit = 0
    guard = None
    if out is not None:
        files = [m for m in maps if os.path.exists(m)]
        guard = _unforeseen.ResultsGuard(os.fspath(out), files, force=force)
        if force:
            open(out, "w").close()
        _refuse_repeats(out, maps, seeds, method or getattr(policy, "method", None), guard)
    fh = open(out, "a", encoding="utf-8") if out is not None else None
    try:
        for m in maps:
            for s in seeds:
                pol = policy_of(s)
                name = method or getattr(pol, "method", None)
                if not name:
                    raise ValueError("evaluate: name the method (method='dqn-kinematic' or a policy.method)")
                learns = bool(getattr(pol, "learns", False))
                runs = [(p, [p]) for p in protocols] if learns else [(protocols[0], protocols)]
                for proto, covers in runs:
                    results = evaluate_policy(pol, m, episodes, proto, seed)
                    line = _line(unit, m, name, proto, list(covers), s, train_episodes, seed, results,
                                 _efe_tree(getattr(pol, "_params", {})))
                    unit += 1
                    lines.append(line)
                    if fh is not None:
                        fh.write(json.dumps(line) + "\n")
                        fh.flush()
    finally:
        if fh is not None:
            fh.close()
        if guard is not None:
            guard.release()
    return EvaluateResult(lines)


def _refuse_repeats(out: Any, maps: list[str], seeds: list[int | None], method: str | None, guard: Any) -> None:
    """Refuses an ``out`` that already holds a line of one of these (map, method,
    training seed): the summary would count it twice."""
    if not method or not os.path.isfile(out):
        return
    names = {_source(m)[0] for m in maps}
    with open(out, encoding="utf-8") as f:
        for number, text in enumerate(f, 1):
            if text.startswith('{"run":') or not text.strip():
                continue
            line = json.loads(text)
            if line.get("method") == method and line.get("scenario") in names and line.get("train_seed") in seeds:
                guard.release()
                raise ValueError(
                    f"{os.fspath(out)}: line {number} is already {method} on {line['scenario']} (training seed "
                    f"{line['train_seed']}); a second line would be counted twice: give another out, or remove it"
                )


def summarize(path: str | os.PathLike[str]) -> list[dict[str, Any]]:
    """The batch summary over training seeds of a results file (``results.summary.json``'s
    rows: means with 95% intervals and the worst seed), computed by the Rust code
    ``unforeseen batch`` uses. A path that is not a file is a ``ValueError``."""
    if not os.path.isfile(path):
        raise ValueError(f"{os.fspath(path)}: not a results file (no such file); give the file `evaluate` or `batch` wrote")
    return json.loads(_unforeseen.summarize_json(os.fspath(path)))

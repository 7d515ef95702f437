"""Python policies as methods in the tables: :func:`evaluate` runs any policy on the
maps by the library's episode loop (the Rust runner of ``unforeseen eval`` and
``unforeseen batch``, which calls the policy each tick) and returns lines of the batch
results schema (``unforeseen_harness::runs::batch::ResultLine``), built by the library
from the same figures as the built-in methods' lines; the batch summary
(:func:`summarize`) and ``unforeseen plot-sweep`` read them beside the built-in methods.
Python computes no figure.

**The policy protocol** (the one way a Python policy is given, to :func:`evaluate`,
:func:`evaluate_policy` and, as a habit, to :class:`~unforeseen.ScaledWrapper`):

* ``act(obs) -> action``: an object with this method (a function ``obs -> action`` is
  accepted where a policy alone is expected: :func:`evaluate_policy`; in
  :func:`evaluate` a callable without ``act`` is a factory ``train_seed -> policy``).
  ``obs`` is the observation the Gymnasium env (:class:`~unforeseen.UnforeseenEnv`)
  gives: int64 ``(d, v, L, p)`` as observed, or the float32 kinematic vector; ``action``
  an integer 0 (maintain), 1 (speed up) or 2 (slow down);
* optional ``reset(seed)``: called at the start of every episode, with the episode's
  controller seed (for a policy that samples);
* optional attributes ``observation`` (``"discrete"``, the default, or ``"kinematic"``:
  the form ``obs`` takes) and ``method`` (its name in the lines).

A habit of :class:`~unforeseen.ScaledWrapper` follows the same protocol with
``probs(obs) -> probabilities`` (or a callable ``obs -> probabilities``) in place of
``act``. A plain policy does not learn across episodes (nothing but ``obs`` reaches it),
so it runs once and its line covers every protocol asked; the scaled agent around a
habit learns (unless ``learning=False``) and runs once per protocol, each run from the
agent as built (zero-shot: afresh every episode).

The episodes are those of ``unforeseen eval`` for a method of the policy's name: the
world seeds derive from the evaluation seed, the map and the episode (every method meets
the same pedestrians), the controller seeds (``reset(seed)``) from the method's name too
(:func:`unforeseen.eval_seeds`). So a policy named after a built-in method that acts as
it does (``never-brake``: always speed up) gives that method's line, timing aside.
Exceptions raised by the policy (and ``KeyboardInterrupt``) propagate as they were.
"""

from __future__ import annotations

import json
import os
import sys
from typing import Any, Iterable, Mapping

from . import _unforeseen
from .wrapper import ScaledWrapper

__all__ = ["EvaluateResult", "evaluate", "evaluate_policy", "summarize", "PROTOCOLS"]

PROTOCOLS = ("zero-shot", "continual")


def _runs(
    policy: Any,
    map: str,
    method: str,
    protocols: list[str],
    episodes: int,
    seed: int,
    train_seed: int | None = None,
    train_episodes: int | None = None,
    first_unit: int = 0,
) -> list[_unforeseen.PolicyRun]:
    """Each run of ``policy`` on ``map``, by the library: its line and episodes."""
    if isinstance(policy, ScaledWrapper):
        target, observation = policy._inner, policy.observation
    else:
        target, observation = policy, getattr(policy, "observation", "discrete")
    return _unforeseen.evaluate_policy(target, os.fspath(map), method, protocols, episodes, seed, train_seed,
                                       train_episodes, first_unit, observation)


def evaluate_policy(
    policy: Any,
    map: str,
    episodes: int = 100,
    protocol: str = "zero-shot",
    seed: int = 7,
    method: str | None = None,
) -> list[dict[str, Any]]:
    """Runs ``policy`` (the module's protocol, or a :class:`~unforeseen.ScaledWrapper`)
    for ``episodes`` evaluation episodes of ``map`` (an embedded name or a map file)
    under ``protocol`` by the library's episode loop, with the episodes of a method named
    ``method`` (default: the policy's ``method`` attribute, else ``"policy"``). Returns
    the episodes as eval.json holds them: per episode ``ret``, ``success``,
    ``collision``, ``timeout``, ``red_lights``, ``ticks``, ``reasoning_ticks``,
    ``decide_ns`` and ``reasoning_ns`` (nanoseconds inside the controller) and
    ``jaywalk_surprise``."""
    name = method or getattr(policy, "method", None) or "policy"
    [run] = _runs(policy, map, name, [protocol], episodes, seed)
    return run.episodes


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
    maps: Iterable[str | os.PathLike[str]],
    seeds: Iterable[int | None],
    episodes: int = 100,
    protocol: str | Iterable[str] = ("zero-shot", "continual"),
    out: str | os.PathLike[str] | None = None,
    method: str | None = None,
    seed: int = 7,
    train_episodes: int | None = None,
    force: bool = False,
    append: bool = False,
) -> EvaluateResult:
    """Evaluates a policy per training seed on every map under every protocol and
    returns the batch result lines (dicts, in an :class:`EvaluateResult`: ``print()`` it
    for the summary table ``unforeseen batch`` prints).

    With ``out``, the lines are written to that JSON Lines file once every unit has run
    (atomically: an interrupted call leaves the file as it was). An earlier results file
    there is replaced, as ``unforeseen batch`` replaces its own, with a notice on stderr
    naming it and its line count, so a notebook cell can be run again; with ``append``,
    the lines are added after the file's lines instead (beside the lines of other
    methods), and a line of the same map, method and training seed already there is
    refused (the summary would count it twice). ``out`` is checked first as ``unforeseen
    batch --out`` is: a ``ValueError`` if it is one of the map files, if it holds
    something other than result lines (unless ``force``: then it is replaced; with
    ``append`` a batch run's file is accepted, its lines kept, and without it refused, so
    that its run is not lost), or if another run is writing it.

    ``policy``: a policy (the module's protocol) or a :class:`~unforeseen.ScaledWrapper`,
    a mapping ``train_seed -> policy`` or a callable ``train_seed -> policy`` (the policy
    trained with that seed). ``maps``: embedded names or map files, each once.
    ``seeds``: the training seeds, each once (``None`` for a policy without one).
    ``protocol``: ``"zero-shot"``, ``"continual"`` or both; a plain policy runs once and
    its line covers every protocol asked (as the batch does for methods that do not
    learn), a wrapper that learns runs once per protocol. ``method``: the name in the
    lines, from which the episodes' controller seeds derive (default: the policy's
    ``method`` attribute). ``seed``: the evaluation seed (the batch's ``--seed``).
    ``train_episodes``: what the lines record as the policy's training episodes. A bad
    argument raises ``ValueError`` naming it before any episode runs."""
    protocols = [protocol] if isinstance(protocol, str) else list(protocol)
    for p in protocols:
        if p not in PROTOCOLS:
            raise ValueError(f"protocol {p!r}: expected one of {PROTOCOLS}")
    maps = [maps] if isinstance(maps, (str, os.PathLike)) else list(maps)
    seeds = list(seeds)
    if not maps or not seeds or not protocols:
        raise ValueError("evaluate: give at least one map, one training seed and one protocol")
    arg = _unforeseen.argument
    seeds = [None if s is None else arg(f"seeds[{i}]", "seed", s) for i, s in enumerate(seeds)]
    for i, s in enumerate(seeds):
        if s in seeds[:i]:
            raise ValueError(f"seeds: {s} is listed twice; give each training seed once")
    episodes = arg("episodes", "episodes", episodes)
    seed = arg("seed", "seed", seed)
    if train_episodes is not None:
        train_episodes = arg("train_episodes", "episodes", train_episodes)
    if method is not None:
        method = arg("method", "text", method)
    names = [name for name, _ in _unforeseen.scenario_sources(maps)]

    def policy_of(s: int | None) -> Any:
        if isinstance(policy, Mapping):
            return policy[s]
        if callable(policy) and not hasattr(policy, "act"):
            return policy(s)
        return policy

    guard = None
    kept = ""
    if out is not None:
        out = arg("out", "path", out)
        files = [os.fspath(m) for m in maps if os.path.exists(m)]
        guard = _unforeseen.ResultsGuard(out, files, force=force, append=append)
    try:
        if out is not None and os.path.isfile(out):
            if append:
                kept = _kept(out, names, seeds, method or getattr(policy, "method", None))
            else:
                _say_replacing(out)
        lines = []
        texts = []
        unit = 0
        for m in maps:
            for s in seeds:
                pol = policy_of(s)
                name = method or getattr(pol, "method", None)
                if not name:
                    raise ValueError("evaluate: name the method (method='dqn-kinematic' or a policy.method)")
                for run in _runs(pol, m, name, protocols, episodes, seed, s, train_episodes, unit):
                    unit += 1
                    lines.append(run.line)
                    texts.append(run.line_text + "\n")
        if out is not None:
            _unforeseen.write_atomic(out, kept + "".join(texts))
    finally:
        if guard is not None:
            guard.release()
    return EvaluateResult(lines)


def _say_replacing(out: str) -> None:
    """The notice of a results file replaced (``unforeseen batch``'s, on stderr)."""
    with open(out, encoding="utf-8", errors="replace") as f:
        count = sum(1 for text in f if text.strip())
    print(
        f"unforeseen.evaluate: replacing {out} ({_lines(count)}) from an earlier run; append=True adds to it instead",
        file=sys.stderr,
    )


def _lines(n: int) -> str:
    return f"{n} line" if n == 1 else f"{n} lines"


def _kept(out: str, names: list[str], seeds: list[int | None], method: str | None) -> str:
    """The text of ``out`` to keep before the new lines (ending in a newline), refusing a
    line of one of these (map, method, training seed): the summary would count it twice."""
    with open(out, encoding="utf-8") as f:
        text = f.read()
    if method:
        for number, line_text in enumerate(text.splitlines(), 1):
            if line_text.startswith('{"run":') or not line_text.strip():
                continue
            line = json.loads(line_text)
            if line.get("method") == method and line.get("scenario") in names and line.get("train_seed") in seeds:
                raise ValueError(
                    f"{out}: line {number} is already {method} on {line['scenario']} (training seed "
                    f"{line['train_seed']}); a second line would be counted twice: give another out, or remove it"
                )
    return text if not text or text.endswith("\n") else text + "\n"


def summarize(path: str | os.PathLike[str], partial: bool = False) -> list[dict[str, Any]]:
    """The batch summary over training seeds of a results file (``results.summary.json``'s
    rows: means with 95% intervals and the worst seed), computed by the Rust code
    ``unforeseen batch`` uses. A path that is not a file is a ``ValueError``. The file is
    read against the run its first line names, as ``unforeseen plot-sweep`` reads it: a
    file of two runs is a ``ValueError``, and so is a partial run (a shard, a run cut
    short), listing the missing units, unless ``partial=True``. Lines without a run
    (``evaluate``'s) are read whole."""
    if not os.path.isfile(path):
        raise ValueError(f"{os.fspath(path)}: not a results file (no such file); give the file `evaluate` or `batch` wrote")
    return json.loads(_unforeseen.summarize_json(os.fspath(path), partial))

"""``unforeseen estimate`` in this process: how rare a method's failures are on a space of
map variations (README, "How rare is a failure"), P(an episode fails) and P(fails | fair)
with their intervals, with the arguments of the library's estimate request and the same
folder of outputs (``estimate.jsonl``, ``summary.json``), byte for byte, as the command
line writes them. The request is planned, its agents trained and the estimate run by
the library (``unforeseen_harness::runs::estimate``)."""

from __future__ import annotations

import json
import os
from collections.abc import Iterable
from typing import Any

from . import _unforeseen


def estimate(
    space: str | os.PathLike[str] | None = None,
    *,
    map: str | os.PathLike[str] = "jaywalk",
    method: str = "scaled",
    protocol: str = "zero-shot",
    estimator: str = "mc",
    target_rel_error: float = 0.3,
    budget: int = 2000,
    episodes: int = 4,
    seed: int = 7,
    jobs: int | None = None,
    shard: str | None = None,
    resume: bool = False,
    out: str | os.PathLike[str] = "out/estimate",
    force: bool = False,
    agent: str | os.PathLike[str] | None = None,
    train_seeds: Iterable[int] | str | None = None,
    train_map: str | os.PathLike[str] = "intersection",
    train_episodes: int = 6000,
    timeout_as: str = "truncation",
    cache: str | os.PathLike[str] | None = None,
) -> dict[str, Any]:
    """Estimates P(an episode of ``method`` fails) and P(fails | fair) when the scenario is
    drawn uniformly from ``space`` (a space file over the base ``map``), as ``unforeseen
    estimate`` does: by ``estimator`` (``"mc"``, plain Monte Carlo with the Wilson
    interval, or ``"is"`` / ``"is-fails"``, cross-entropy importance sampling aimed at
    P(fails | fair) / P(fails), with a weighted interval), at
    most ``budget`` draws of ``episodes`` episodes each, stopping once the relative
    half-width of what the estimator aims at (both probabilities for ``"mc"``, P(fails |
    fair) for ``"is"``, P(fails) for ``"is-fails"``) is at most ``target_rel_error``.
    Agents: ``agent`` (an agent file), one per training seed (``train_seeds``, trained
    on ``train_map``, a map file or an embedded name, for ``train_episodes`` and kept in
    ``cache`` when given), or, with neither, one trained on ``train_map`` with ``seed``. ``jobs`` threads (None: every
    core; the results do not depend on it); ``force`` replaces files in ``out`` an
    estimate did not write.

    ``resume=True`` keeps the draws an earlier run of the same request left in ``out``
    (interrupted, or shards' files concatenated there) and evaluates only the rest: the
    files are those of a run never interrupted. ``shard="I/N"`` evaluates only shard I of
    N of the next stage (the draws I-1 mod N of the first stage ``out`` does not complete)
    and writes ``estimate.jsonl`` alone, as ``unforeseen estimate --shard`` does.

    Writes the folder ``out`` and returns ``summary.json``'s contents (for a shard, what it
    evaluated: ``shard``, ``stage``, ``share``, ``evaluated``, ``draws``). ``ValueError``
    names a bad argument (``target_rel_error: ...``, ``shard: ...``), map or space before
    any work, and a file in ``out`` that ``resume`` cannot continue (naming its line);
    Ctrl-C raises ``KeyboardInterrupt``, the draws evaluated so far kept for ``resume``."""
    fields = dict(locals())
    if space is None:
        fields.pop("space")
    return json.loads(_unforeseen.estimate(fields))

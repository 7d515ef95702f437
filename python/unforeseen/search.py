"""``unforeseen search`` in this process: the search for the fair scenarios where a method
fails (README, "Searching for the unforeseen"), with the arguments of
:func:`unforeseen.distributed.run_search` (the library's search request) and the same
folder of outputs (``candidates.jsonl``, ``summary.json``, ``failures/*.ron``,
``search.svg``), timing fields aside, as the command line writes them. The request is
planned, its agents trained and the stages run by the library
(``unforeseen_harness::runs::search``)."""

from __future__ import annotations

import json
import os
from collections.abc import Iterable
from typing import Any

from . import _unforeseen


def search(
    space: str | os.PathLike[str] | None = None,
    *,
    map: str | os.PathLike[str] = "jaywalk",
    method: str = "scaled",
    protocol: str = "zero-shot",
    budget: int = 100,
    episodes: int = 20,
    seed: int = 7,
    sobol_share: float = 0.5,
    rounds: int = 5,
    max_failures: int = 5,
    jobs: int | None = None,
    shard: str | None = None,
    resume: bool = False,
    out: str | os.PathLike[str] = "out/search",
    force: bool = False,
    agent: str | os.PathLike[str] | _unforeseen.Agent | None = None,
    train_seeds: Iterable[int] | str | None = None,
    train_map: str | os.PathLike[str] = "intersection",
    train_episodes: int = 6000,
    timeout_as: str = "truncation",
    cache: str | os.PathLike[str] | None = None,
    command: str | None = None,
) -> dict[str, Any]:
    """Searches ``space`` (a space file over the base ``map``) for the fair scenarios where
    ``method`` fails under ``protocol``, as ``unforeseen search`` does: ``budget``
    candidates (``sobol_share`` of them scrambled Sobol points, the rest in ``rounds``
    adaptive rounds), ``episodes`` each, then up to ``max_failures`` failures minimised
    toward the base. Agents: ``agent`` (an agent file, or an :class:`unforeseen.Agent`),
    one per training seed (``train_seeds``, ``range(1, 4)`` or ``"1..3"``, trained on
    ``train_map``, a map file or an embedded name, for ``train_episodes``, and kept in the
    agent cache ``cache`` when one is given: e.g. ``"out/agents"``, the command line's),
    or, with neither, one trained on ``train_map`` with ``seed``. ``jobs`` threads (None: every
    core); ``shard`` (``"I/N"``) evaluates one slice of the Sobol stage; ``resume`` keeps
    the finished candidates in ``out``; ``force`` replaces files there a search did not
    write; ``command`` goes in the failure maps' comments.

    Writes the folder ``out`` and returns ``summary.json``'s contents. ``ValueError``
    names a bad argument (``budget: ...``), map or space before any work; Ctrl-C raises
    ``KeyboardInterrupt``."""
    fields = dict(locals())
    fields.pop("command")
    given = fields.pop("agent") if isinstance(agent, _unforeseen.Agent) else None
    if space is None:
        fields.pop("space")
    said = command if command is not None else f"unforeseen.search(space={str(space)!r}, ...)"
    return json.loads(_unforeseen.search(fields, given, said))

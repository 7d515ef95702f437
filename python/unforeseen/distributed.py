"""Batch runs across machines on a Ray cluster, with the results one machine writes.

:func:`run_batch` takes the arguments of :func:`unforeseen.batch` (the batch request, the
fields and defaults of ``unforeseen batch``), connects to a running
cluster (``address="auto"``, or one given), and runs the batch as Ray tasks through the
Rust binding (not the command line), a block of units per task with the GIL released::

    from unforeseen.distributed import run_batch
    report = run_batch(["maps/"], train_seeds=range(1, 5), episodes=20, out="sweep.jsonl")

or, from a shell, ``python -m unforeseen.distributed batch maps/ --train-seeds 1..4
--episodes 20 --out sweep.jsonl`` (the options of ``unforeseen batch``, derived from the
request's fields, plus ``--address`` and ``--units-per-task``).

How it runs
-----------
* The driver plans the run as ``batch`` does (its units, the run identity written as the
  results file's first line, and with ``resume`` the lines an earlier run of it kept).
* Each training seed the remaining units need is trained once, by one task on the
  cluster; its agent (a few MB of agent-file text) goes to the object store, and every
  unit task that needs it receives it from there.
* Units run in blocks (``units_per_task``); each task rebuilds the run from the plan's
  ``spec`` and refuses to run if what it rebuilt differs from the driver's run (a node
  with other maps). Results do not depend on the number of workers or the order tasks
  finish in: each unit's seeds derive from its identity, never from where it runs.
* Lines are appended to the results file as tasks finish; at the end the file is
  rewritten in canonical order with its summary, atomically, by ``unforeseen merge``'s
  library code. The file then equals ``unforeseen batch``'s, timing fields aside.

Faults
------
* A worker process or node that dies loses nothing: its tasks are retried
  (``max_retries``), and an agent whose only copy was on a lost node is trained again
  by Ray's lineage reconstruction.
* A driver killed mid-run leaves the lines that had finished; the same call (command)
  with ``resume=True`` (``--resume``) keeps them and runs only the rest, under the run
  identity rules of ``batch``.
* An error in the input (a bad map, a node whose maps differ) raises ``ValueError`` in
  the task; such a task is not retried (``retry_exceptions=False``: it would fail the
  same way everywhere) and the run fails once with that message.

Network
-------
Usage statistics are switched off for the driver (``RAY_USAGE_STATS_ENABLED=0``); start
the cluster's nodes with ``--disable-usage-stats`` too. The README shows a cluster kept
on loopback inside a network namespace (the tests do the same).

How a search runs
-----------------
:func:`run_search` takes the arguments of :func:`unforeseen.search` (the search
request) and keeps the search's stages in Rust (``unforeseen::search::run_with``,
through the binding's ``drive_search``): the Sobol stage, each cross-entropy round and
each minimisation try hand their candidates to an evaluator, which here splits them into
blocks and runs them as Ray tasks through :func:`_drive` (the same retry and input-error
rules as :func:`run_batch`; each training seed trained once and shared). The outputs are
those of ``unforeseen search`` with the same arguments, timing aside. The search driver
shows no progress bar; it passes the output guard and takes the lock of ``unforeseen search``
(``OUT/.lock``). Ctrl-C stops it within a fraction of a second (the binding sets an
event the evaluator checks between waits; pending tasks are cancelled) and raises
``KeyboardInterrupt``; the finished candidates stay for ``resume=True``.

How an estimate runs
--------------------
:func:`run_estimate` takes the arguments of :func:`unforeseen.estimate` and keeps the
estimator's stages in Rust (through the binding's ``drive_estimate``): each block of
draws (each cross-entropy round, each block of the final or Monte Carlo stage) goes to
the same evaluator as a search's candidates, so ``estimate.jsonl`` and ``summary.json``
equal ``unforeseen estimate``'s byte for byte. The draws evaluated stream to
``estimate.jsonl.part``: an interrupted estimate continues with ``resume=True``
(``--resume``), whose blocks send only the missing draws to the cluster; ``shard`` is
refused (the cluster deals the draws itself).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
import threading
import time
from collections.abc import Callable, Iterable, Sequence
from pathlib import Path
from typing import Any

from . import _unforeseen
from .requests import BATCH_DEFAULTS, ESTIMATE_DEFAULTS, SEARCH_DEFAULTS, flag, flag_message

__all__ = ["DEFAULT_MAX_RETRIES", "main", "run_batch", "run_estimate", "run_search"]

#: Retries of a task whose worker process or node died (system failures only).
DEFAULT_MAX_RETRIES = 3

#: Seconds between progress redraws; and the longest wait for any task before the
#: driver checks again (it waits on task completion, never sleeps).
_TICK = 1.0

#: The longest wait for any task when a stop event is given (Ctrl-C in the search
#: driver): it is checked between waits.
_STOP_TICK = 0.2


def _ray() -> Any:
    os.environ.setdefault("RAY_USAGE_STATS_ENABLED", "0")
    try:
        import ray
    except ImportError as e:  # pragma: no cover - depends on the install
        raise ImportError(
            "unforeseen.distributed needs Ray: pip install './python[ray]' (or pip install 'unforeseen[ray]')"
        ) from e
    return ray


def _check_task_options(jobs: int, per_task_name: str, per_task: int | None, max_retries: int) -> None:
    """Raises ``ValueError`` for task options out of range (threads per task, work items per
    task, retries), before Ray is needed."""
    if jobs < 1 or jobs > 256:
        raise ValueError(f"jobs {jobs}: expected a number of threads per task from 1 to 256")
    if per_task is not None and per_task < 1:
        raise ValueError(f"{per_task_name} {per_task}: expected at least 1")
    if max_retries < 0:
        raise ValueError(f"max_retries {max_retries}: expected 0 or more")


def _task_options(max_retries: int) -> dict[str, Any]:
    """Ray options of every task: retried when its worker or node dies, never for an
    exception it raises (an input error fails the same way on every attempt)."""
    return {"max_retries": max_retries, "retry_exceptions": False}


def _train_task(seed: int, episodes: int, train_map: str = "intersection", timeout_as: str = "truncation") -> bytes:
    """One agent, trained on the node that runs the task."""
    return _unforeseen.train_agent(seed, episodes, train_map, timeout_as)


def _units_task(spec: str, seeds: Sequence[int | None], *agents: bytes, units: list[int], threads: int) -> list[str]:
    """A block of units: their result lines (JSON text)."""
    return _unforeseen.run_units(spec, list(zip(seeds, agents, strict=True)), units, threads)


def _search_task(
    spec: str, seeds: Sequence[int | None], *agents: bytes, candidates: list[str], from_file: bool, threads: int
) -> list[list[str]]:
    """A block of search candidates: each one's lines of ``candidates.jsonl``."""
    return _unforeseen.evaluate_search_candidates(
        spec, list(zip(seeds, agents, strict=True)), candidates, from_file, threads
    )


class _Progress:
    """Units done / total, rate and ETA on one stderr line, only when stderr is a terminal."""

    def __init__(self, total: int, done: int, quiet: bool) -> None:
        self.total, self.done, self.start_done = total, done, done
        self.on = not quiet and sys.stderr.isatty()
        self.started = time.monotonic()
        self.drawn = 0.0

    def advance(self, n: int) -> None:
        self.done += n
        now = time.monotonic()
        if self.on and (now - self.drawn >= _TICK or self.done == self.total):
            self.drawn = now
            ran = self.done - self.start_done
            rate = ran / max(now - self.started, 1e-9)
            left = (self.total - self.done) / rate if rate > 0 else math.inf
            eta = "?" if math.isinf(left) else f"{int(left) // 60}m{int(left) % 60:02d}s"
            sys.stderr.write(f"\r{self.done}/{self.total} units, {rate:.2f} units/s, ETA {eta}   ")
            sys.stderr.flush()

    def finish(self) -> None:
        if self.on:
            sys.stderr.write("\n")
            sys.stderr.flush()


def _app_error(ray: Any, err: BaseException) -> BaseException | None:
    """The input error (ValueError) a task raised, if that is what `err` is."""
    cause = getattr(err, "cause", None)
    if isinstance(err, ray.exceptions.RayTaskError) and isinstance(cause, ValueError):
        return cause
    return None


def _drive(
    ray: Any,
    blocks: list[list[int]],
    submit: Callable[[list[int]], Any],
    sink: Callable[[list[int], list[str]], None],
    stop: threading.Event | None = None,
) -> None:
    """Submits every block as a task and hands each finished block's lines to `sink`, in
    the order they finish. An input error of any task cancels the rest and raises it as
    `ValueError`; a task lost after its retries raises `RuntimeError`; `stop` set (Ctrl-C
    in the search driver, which waits on this from another thread) cancels the rest and
    raises `KeyboardInterrupt` within ``_STOP_TICK`` seconds."""
    pending = {submit(b): b for b in blocks}
    try:
        while pending:
            if stop is not None and stop.is_set():
                raise KeyboardInterrupt
            ready, _ = ray.wait(list(pending), num_returns=1, timeout=_TICK if stop is None else _STOP_TICK)
            for ref in ready:
                block = pending.pop(ref)
                try:
                    lines = ray.get(ref)
                except ray.exceptions.RayError as e:
                    cause = _app_error(ray, e)
                    if cause is not None:
                        raise ValueError(str(cause)) from None
                    raise RuntimeError(
                        f"units {block[0]}..{block[-1]}: the task failed after its retries ({type(e).__name__}): {e}"
                    ) from None
                sink(block, lines)
    finally:
        for ref in pending:
            ray.cancel(ref, force=True)


def _task_request(job: str, fields: dict[str, Any], per_task_name: str, per_task: int | None, max_retries: int,
                  shards_instead: str) -> tuple[int, _unforeseen.Agent | None]:
    """The request of ``job`` as the driver takes it (``fields``, changed in place): the shard
    refused (the cluster splits the run itself; ``shards_instead`` says how shards run
    elsewhere end), the task options checked, and an agent given loaded taken out of the
    fields. Returns the threads of each task and that agent."""
    shard = fields.get("shard")
    if shard is not None:
        raise ValueError(
            f"shard {shard}: the cluster splits the run itself; run it whole here, "
            f"or run `unforeseen {job} --shard I/N` on separate machines and {shards_instead}"
        )
    jobs = fields.get("jobs")
    threads = 1 if jobs is None else jobs
    _check_task_options(threads, per_task_name, per_task, max_retries)
    given = fields.pop("agent") if isinstance(fields.get("agent"), _unforeseen.Agent) else None
    return threads, given


def _connect(ray: Any, address: str | None) -> None:
    """Connects to the cluster at ``address`` unless Ray is connected already."""
    if not ray.is_initialized():
        ray.init(address=address, include_dashboard=False, log_to_driver=False)


def run_batch(
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
    agent: str | os.PathLike[str] | _unforeseen.Agent | None = None,
    train_seeds: Iterable[int] | str | None = None,
    train_map: str = "intersection",
    train_episodes: int = 6000,
    timeout_as: str = "truncation",
    cache: str | os.PathLike[str] | None = None,
    units_per_task: int | None = None,
    address: str | None = "auto",
    max_retries: int = DEFAULT_MAX_RETRIES,
    quiet: bool = False,
) -> _unforeseen.BatchResult:
    """``unforeseen batch`` on a Ray cluster (see the module's documentation): the
    arguments of :func:`unforeseen.batch` (the batch request, planned by the library as
    the command line plans it), and the same results file ``out`` and summary, timing
    fields aside. On the cluster ``jobs`` is the threads, and CPUs, of each task (None:
    1); agents train once per seed on the cluster and are not cached (``cache`` is not
    used); ``shard`` is refused (the cluster splits the run itself).

    Ray's own: ``units_per_task`` (default: about 4 tasks per CPU), ``address`` (connects
    with ``ray.init(address)`` unless Ray is connected already), ``max_retries`` and
    ``quiet``. A bad argument raises ``ValueError`` naming it before any task runs.
    Returns the report :func:`unforeseen.batch` returns (a :class:`BatchResult`) of the
    finished file: ``print(result)`` gives the summary table ``batch`` prints,
    ``result.lines`` the file's lines, ``result.summary`` the summary's rows, and
    ``result.failures`` the expectations failed on the mean over training seeds, in
    ``batch``'s words (the command exits 1 on any, as ``batch`` does).
    """
    fields = {k: v for k, v in locals().items() if k in BATCH_DEFAULTS}
    threads, given = _task_request("batch", fields, "units_per_task", units_per_task, max_retries,
                                   "`unforeseen merge` the parts")
    out = Path(out)
    # Bad input, then a missing Ray, refused before the plan's guard removes an earlier summary.
    _unforeseen.check_batch(fields, given)
    ray = _ray()
    plan = json.loads(_unforeseen.plan_batch(fields, given))
    # The lock and the writer of `unforeseen batch` (OUT.lock; a temporary file renamed).
    lock = _unforeseen.ResultsGuard(os.fspath(out), [], force=True)
    try:
        # Every check has passed (the plan's, Ray's import): the earlier run's summary
        # goes, so it never describes this run's lines.
        Path(plan["summary"]).unlink(missing_ok=True)
        _unforeseen.write_atomic(os.fspath(out), plan["head"])
        _connect(ray, address)
        options = _task_options(max_retries)
        # One agent per training seed the remaining units need, in the object store.
        if plan["agent"] is not None:
            agent_refs = {plan["todo_seeds"][0] if plan["todo_seeds"] else None: ray.put(plan["agent"].encode())}
        else:
            train = ray.remote(num_cpus=1, **options)(_train_task)
            t = plan["train"]
            agent_refs = {s: train.remote(s, t["episodes"], t["map"], t["timeout_as"]) for s in plan["train_seeds_to_run"]}
        todo: list[int] = plan["todo"]
        seed_of = dict(zip(todo, plan["todo_seeds"], strict=True))
        if units_per_task is None:
            cpus = max(1, int(ray.cluster_resources().get("CPU", 1)) // threads)
            units_per_task = max(1, math.ceil(len(todo) / (4 * cpus)))
        blocks = [todo[i : i + units_per_task] for i in range(0, len(todo), units_per_task)]
        run = ray.remote(num_cpus=threads, **options)(_units_task)

        def submit(block: list[int]) -> Any:
            # The block's agents (a scripted method's units need none: none is trained for them).
            seeds = sorted({seed_of[u] for u in block} & agent_refs.keys(), key=lambda s: (s is None, s or 0))
            return run.remote(plan["spec"], seeds, *(agent_refs[s] for s in seeds), units=block, threads=threads)

        progress = _Progress(plan["total"], plan["kept"], quiet)
        with open(out, "a", encoding="utf-8") as f:

            def sink(_block: list[int], lines: list[str]) -> None:
                f.write("".join(lines))
                f.flush()
                progress.advance(len(lines))

            try:
                _drive(ray, blocks, submit, sink)
            finally:
                progress.finish()
        return _unforeseen.finish_batch(str(out))
    finally:
        lock.release()


def run_search(
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
    candidates_per_task: int | None = None,
    address: str | None = "auto",
    max_retries: int = DEFAULT_MAX_RETRIES,
) -> dict[str, Any]:
    """``unforeseen search`` on a Ray cluster: the arguments of :func:`unforeseen.search`
    (the search request, checked by the library as the command line checks it), and the
    same folder of outputs (``candidates.jsonl``, ``summary.json``, ``failures/*.ron``,
    ``search.svg``), timing fields aside, whatever the number of workers. On the cluster
    ``jobs`` is the threads, and CPUs, of each task (None: 1); agents train once per seed
    on the cluster and are not cached (``cache`` is not used); ``shard`` is refused.

    The stages run in order on the driver, in the library (``unforeseen::search``); each
    stage's candidates (the Sobol stage's, each adaptive round's) run as tasks of
    ``candidates_per_task`` candidates (default: about 4 tasks per CPU), and each
    minimisation try as a task of its own, the best failures minimised at once. Agents
    reach the tasks through the object store. ``command`` is written in the failure maps'
    comments (``Found by: ...``). Returns ``summary.json``'s contents.
    """
    fields = {k: v for k, v in locals().items() if k in SEARCH_DEFAULTS}
    if space is None:
        fields.pop("space")
    threads, given = _task_request("search", fields, "candidates_per_task", candidates_per_task, max_retries,
                                   "finish with --resume")
    # The request, maps and space checked before any task runs.
    plan = json.loads(_unforeseen.plan_search(fields, given))
    from_file = plan["agent"] is not None
    # Set by the binding on Ctrl-C: `evaluate` runs on the driver's other threads, which
    # never see the signal themselves.
    stop = threading.Event()
    agents, evaluate = _candidate_tasks(plan, plan["spec"], from_file, threads, candidates_per_task, address,
                                        max_retries, stop)
    summary = _unforeseen.drive_search(
        plan["spec"],
        agents,
        evaluate,
        from_file=from_file,
        jobs=max(1, max_failures),
        command=command if command is not None else f"unforeseen.distributed.run_search(space={str(space)!r}, ...)",
        stop=stop,
    )
    return json.loads(summary)


def _candidate_tasks(
    plan: dict[str, Any],
    spec: str,
    from_file: bool,
    threads: int,
    candidates_per_task: int | None,
    address: str | None,
    max_retries: int,
    stop: threading.Event,
) -> tuple[list[tuple[int | None, bytes]], Callable[[list[str]], list[list[str]]]]:
    """The agents of a planned search or estimate (``plan``: the agent file's text, or the
    training seeds to train, each trained once on the cluster), as ``(training seed,
    agent text)`` pairs, and the evaluator of the search ``spec``'s candidates that the
    binding's driver calls: each call's candidates split into blocks run as Ray tasks
    (``candidates_per_task``, default about 4 tasks per CPU) through :func:`_drive`, the
    agents reaching them through the object store."""
    ray = _ray()
    _connect(ray, address)
    options = _task_options(max_retries)
    pairs: list[tuple[int | None, Any]]
    if from_file:
        pairs = [(None, ray.put(plan["agent"].encode()))]
    else:
        train = ray.remote(num_cpus=1, **options)(_train_task)
        pairs = [(s, train.remote(s, plan["train_episodes"], plan["train_map"], plan["timeout_as"])) for s in plan["train"]]
    agent_seeds = [s for s, _ in pairs]
    refs = [r for _, r in pairs]
    texts = ray.get(refs) if refs else []
    task = ray.remote(num_cpus=threads, **options)(_search_task)
    cpus = max(1, int(ray.cluster_resources().get("CPU", 1)) // threads)

    def evaluate(candidates: list[str]) -> list[list[str]]:
        per = candidates_per_task or max(1, math.ceil(len(candidates) / (4 * cpus)))
        blocks = [list(range(i, min(i + per, len(candidates)))) for i in range(0, len(candidates), per)]
        lines: list[list[str] | None] = [None] * len(candidates)

        def submit(block: list[int]) -> Any:
            return task.remote(
                spec, agent_seeds, *refs, candidates=[candidates[i] for i in block], from_file=from_file,
                threads=threads,
            )

        def sink(block: list[int], got: list[list[str]]) -> None:
            for i, g in zip(block, got, strict=True):
                lines[i] = g

        _drive(ray, blocks, submit, sink, stop)
        return [g for g in lines if g is not None]

    return list(zip(agent_seeds, texts, strict=True)), evaluate


def run_estimate(
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
    candidates_per_task: int | None = None,
    address: str | None = "auto",
    max_retries: int = DEFAULT_MAX_RETRIES,
) -> dict[str, Any]:
    """``unforeseen estimate`` on a Ray cluster: the arguments of :func:`unforeseen.estimate`
    (the estimate request, checked by the library as the command line checks it), and
    the same ``estimate.jsonl`` and ``summary.json``, byte for byte, whatever the number
    of workers. The estimator's stages run in order on the driver, in the library
    (``unforeseen::runs::estimate``); each block of draws runs as tasks of
    ``candidates_per_task`` draws (default: about 4 tasks per CPU), each draw evaluated
    as the search evaluates a candidate. On the cluster ``jobs`` is the threads, and
    CPUs, of each task (None: 1); agents train once per seed on the cluster and are not
    cached (``cache`` is not used); ``shard`` is refused (the cluster deals the draws
    itself), ``resume`` keeps the draws an earlier run of the same request left in
    ``out`` and sends only the rest to the cluster. Returns ``summary.json``'s contents.
    """
    fields = {k: v for k, v in locals().items() if k in ESTIMATE_DEFAULTS}
    if space is None:
        fields.pop("space")
    threads, _ = _task_request("estimate", fields, "candidates_per_task", candidates_per_task, max_retries,
                               "concatenate their estimate.jsonl and finish with --resume")
    plan = json.loads(_unforeseen.plan_estimate(fields))
    stop = threading.Event()
    agents, evaluate = _candidate_tasks(plan, plan["search_spec"], plan["agent"] is not None, threads,
                                        candidates_per_task, address, max_retries, stop)
    return json.loads(_unforeseen.drive_estimate(plan["spec"], agents, evaluate, stop=stop))


def _request_options(parser: argparse.ArgumentParser, defaults: dict[str, Any], positional: str | None) -> None:
    """One option per field of a request (``defaults``: its fields and defaults, from the
    library), spelt as the command line spells it (:func:`unforeseen.requests.flag`):
    ``positional`` as the arguments, a list as a repeatable option, a flag for a bool,
    ``--no-cache`` for no agent cache."""
    for field, default in defaults.items():
        if field == positional:
            parser.add_argument(field, nargs="*", metavar="MAP|DIR")
        elif isinstance(default, bool):
            parser.add_argument(flag(field), dest=field, action="store_true")
        elif isinstance(default, list):
            parser.add_argument(flag(field), dest=field, action="append", default=[])
        else:
            kind = int if field == "jobs" or isinstance(default, int) else float if isinstance(default, float) else str
            parser.add_argument(flag(field), dest=field, type=kind, default=default)
    if "cache" in defaults:
        parser.add_argument("--no-cache", dest="cache", action="store_const", const=None, default=argparse.SUPPRESS,
                            help="accepted (agents are not cached on the cluster)")


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="python -m unforeseen.distributed", description=__doc__.split("\n\n")[0])
    sub = p.add_subparsers(dest="command", required=True)
    b = sub.add_parser("batch", help="unforeseen batch on a Ray cluster (its options, plus --address)")
    _request_options(b, BATCH_DEFAULTS, positional="maps")
    b.add_argument("--quiet", "-q", action="store_true")
    b.add_argument("--address", default="auto", help="Ray cluster address (default: auto, the local cluster)")
    b.add_argument("--units-per-task", type=int, help="units per task (default: about 4 tasks per CPU)")
    b.add_argument("--max-retries", type=int, default=DEFAULT_MAX_RETRIES)
    s = sub.add_parser("search", help="unforeseen search on a Ray cluster (its options, plus --address)")
    _request_options(s, SEARCH_DEFAULTS, positional=None)
    s.add_argument("--quiet", "-q", action="store_true")
    s.add_argument("--address", default="auto", help="Ray cluster address (default: auto, the local cluster)")
    s.add_argument("--candidates-per-task", type=int, help="candidates per task (default: about 4 tasks per CPU)")
    s.add_argument("--max-retries", type=int, default=DEFAULT_MAX_RETRIES)
    e = sub.add_parser("estimate", help="unforeseen estimate on a Ray cluster (its options, plus --address)")
    _request_options(e, ESTIMATE_DEFAULTS, positional=None)
    e.add_argument("--quiet", "-q", action="store_true")
    e.add_argument("--address", default="auto", help="Ray cluster address (default: auto, the local cluster)")
    e.add_argument("--candidates-per-task", type=int, help="draws per task (default: about 4 tasks per CPU)")
    e.add_argument("--max-retries", type=int, default=DEFAULT_MAX_RETRIES)
    return p


def _main_estimate(args: argparse.Namespace) -> int:
    try:
        summary = run_estimate(
            **{f: getattr(args, f) for f in ESTIMATE_DEFAULTS},
            candidates_per_task=args.candidates_per_task,
            address=args.address,
            max_retries=args.max_retries,
        )
    except ValueError as e:
        print(f"error: {flag_message(str(e), ESTIMATE_DEFAULTS)}", file=sys.stderr)
        return 2
    except (RuntimeError, ConnectionError) as e:
        print(f"error: {e}", file=sys.stderr)
        return 1
    p = summary["estimates"]["p_fail"]
    print(
        f"{summary['evaluations']} draws evaluated; P(fails) {p['p']} [{p['ci95_low']}, {p['ci95_high']}]; "
        f"wrote {args.out}/{{estimate.jsonl, summary.json}}"
    )
    return 0


def _main_search(args: argparse.Namespace, argv: Sequence[str]) -> int:
    try:
        summary = run_search(
            **{f: getattr(args, f) for f in SEARCH_DEFAULTS},
            candidates_per_task=args.candidates_per_task,
            address=args.address,
            max_retries=args.max_retries,
            command=" ".join(["python -m unforeseen.distributed", *argv]),
        )
    except ValueError as e:
        print(f"error: {flag_message(str(e), SEARCH_DEFAULTS)}", file=sys.stderr)
        return 2
    except (RuntimeError, ConnectionError) as e:
        print(f"error: {e}", file=sys.stderr)
        return 1
    c = summary["counts"]
    print(
        f"candidates: {c['sobol']} Sobol, {c['adaptive']} adaptive, {c['minimise']} minimisation tries; "
        f"{len(summary['failures'])} failure(s) written; wrote {args.out}/"
        "{candidates.jsonl, summary.json, search.svg, failures/}"
    )
    return 0


def main(argv: Sequence[str] | None = None) -> int:
    """The command: exit 0, 1 when an expectation fails on the mean, 2 for bad input."""
    argv = list(sys.argv[1:] if argv is None else argv)
    args = _parser().parse_args(argv)
    if args.command == "search":
        return _main_search(args, argv)
    if args.command == "estimate":
        return _main_estimate(args)
    try:
        report = run_batch(
            **{f: getattr(args, f) for f in BATCH_DEFAULTS},
            units_per_task=args.units_per_task,
            address=args.address,
            max_retries=args.max_retries,
            quiet=args.quiet,
        )
    except ValueError as e:
        print(f"error: {flag_message(str(e), BATCH_DEFAULTS)}", file=sys.stderr)
        return 2
    except (RuntimeError, ConnectionError) as e:
        print(f"error: {e}", file=sys.stderr)
        return 1
    print(report)
    summary = Path(args.out).with_suffix(".summary.json")
    print(
        f"wrote {args.out} ({len(report.lines)} lines) and {summary}; "
        f"{report.checked} expectation(s) checked on the mean over training seeds, {len(report.failures)} failed"
    )
    for f in report.failures:
        print(f"expectation failed: {f}", file=sys.stderr)
    return 1 if report.failures else 0


if __name__ == "__main__":
    # Run the package's module (not this `__main__` copy), so tasks refer to its functions.
    from unforeseen.distributed import main as _main

    sys.exit(_main())

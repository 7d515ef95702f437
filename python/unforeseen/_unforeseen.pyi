"""The Rust extension of unforeseen (``unforeseen._unforeseen``).

Python-facing classes live in :mod:`unforeseen` (``UnforeseenEnv``, ``VectorEnv``); this
module is the thin Rust layer under them. Errors: ``ValueError`` for bad input (a map,
an agent file, a parameter, an action), with the message the command line prints;
``RuntimeError`` otherwise.
"""

import os
from typing import Any, Callable, Iterable, Sequence, final

import numpy as np
import numpy.typing as npt

__all__ = [
    "Agent",
    "BatchResult",
    "CompareResult",
    "Controller",
    "Env",
    "EvalResult",
    "PolicyRun",
    "ScaledHabitAgent",
    "VectorEnv",
    "batch",
    "batch_result",
    "compare",
    "embedded_maps",
    "eval_seeds",
    "evaluate",
    "evaluate_policy",
    "load_agent",
    "q_table_habit",
    "rust_loop",
    "scripted_controller",
    "stream_seed",
    "summarize_json",
    "train",
    "version",
]

Info = dict[str, Any]

def version() -> str:
    """The version of the Rust crates this extension was built from."""

def embedded_maps() -> list[str]:
    """Names of the embedded maps (``intersection``, ``jaywalk``, ...)."""

def stream_seed(key: int, episode: int) -> int:
    """World seed of episode ``episode`` of the episode stream keyed ``key``."""

def argument(field: str, kind: str, value: Any) -> Any:
    """``value`` converted as the argument ``field`` of ``kind`` (``"seed"``,
    ``"episodes"``, ``"seeds"``, ``"path"`` or ``"text"``) is everywhere in the extension:
    the converted value, or the ``ValueError`` naming ``field`` (and a number's range)."""

def write_atomic(path: str | os.PathLike[str], text: str) -> None:
    """Writes ``text`` to ``path`` as the library writes its files: a temporary file
    beside it renamed over it."""

def rust_loop(
    map: str | os.PathLike[str],
    actions: Sequence[int],
    steps: int,
    seed: int | None = None,
    observation: str = "discrete",
    overrides: dict[str, Any] | None = None,
) -> tuple[int, float, int]:
    """Steps ``map`` ``steps`` ticks in Rust alone with ``actions`` in turn (GIL released;
    Ctrl-C raises ``KeyboardInterrupt``) from stream key ``seed`` (None: 0):
    ``(ticks, seconds, episodes)``."""

@final
class Env:
    """One env of a map: ``unforeseen_env::Env``."""

    def __init__(
        self,
        map: str,
        observation: str = "discrete",
        pedestrian_slots: int = 4,
        overrides: dict[str, Any] | None = None,
        vehicle_slots: int | None = None,
    ) -> None:
        """``vehicle_slots`` ``None``: 4 on a map with traffic rules, 0 without."""
    @property
    def map_name(self) -> str: ...
    @property
    def map_json(self) -> str:
        """The map as JSON (SI units)."""
    @property
    def observation(self) -> str: ...
    @property
    def factor_sizes(self) -> list[int]:
        """``[n_d, n_v, n_L, n_p]``."""
    @property
    def kinematic_len(self) -> int: ...
    @property
    def pedestrian_slots(self) -> int: ...
    @property
    def vehicle_slots(self) -> int:
        """The configured count, or the map's default."""
    def kinematic_bounds(self) -> tuple[npt.NDArray[np.float32], npt.NDArray[np.float32]]: ...
    @property
    def decision_dt(self) -> float: ...
    @property
    def max_steps(self) -> int: ...
    @property
    def done(self) -> bool: ...
    @property
    def stream_position(self) -> tuple[int, int]:
        """``(key, episodes started)`` of the episode stream."""
    def reset(self, seed: int) -> tuple[npt.NDArray[Any], Info]:
        """Starts an episode with world seed ``seed`` exactly."""
    def set_stream(self, key: int) -> None: ...
    def reset_next(self) -> tuple[npt.NDArray[Any], Info]:
        """Starts the next episode of the stream."""
    def step(self, action: int) -> tuple[npt.NDArray[Any], float, bool, bool, Info]: ...
    def kinematic(self) -> npt.NDArray[np.float32]: ...
    def render_rgb(self, scale: float = 10.0) -> npt.NDArray[np.uint8]:
        """Top-down frame, ``(height, width, 3)`` uint8, ``scale`` pixels per metre."""
    def render_ansi(self) -> str: ...

@final
class VectorEnv:
    """``num_envs`` envs stepped in parallel in Rust (GIL released); autoreset
    ``"next_step"`` (Gymnasium's default) or ``"same_step"`` (the step's info then holds
    ``final_obs`` and ``final_info``)."""

    def __init__(
        self,
        map: str,
        num_envs: int,
        observation: str = "discrete",
        pedestrian_slots: int = 4,
        overrides: dict[str, Any] | None = None,
        num_threads: int | None = None,
        autoreset: str = "next_step",
        vehicle_slots: int | None = None,
    ) -> None: ...
    @property
    def num_envs(self) -> int: ...
    @property
    def obs_len(self) -> int: ...
    def reset(self, keys: Sequence[int]) -> tuple[npt.NDArray[Any], dict[str, Any]]: ...
    def step(
        self, actions: npt.NDArray[np.int64]
    ) -> tuple[
        npt.NDArray[Any], npt.NDArray[np.float64], npt.NDArray[np.bool_], npt.NDArray[np.bool_], dict[str, Any]
    ]: ...
    def render_rgb(self, scale: float = 10.0) -> list[npt.NDArray[np.uint8]]:
        """Every env's top-down frame."""

@final
class Agent:
    """A trained agent (Q-learning, the world model, Bayesian RL)."""

    def save(self, path: str | os.PathLike[str], force: bool = False) -> None: ...
    @property
    def meta(self) -> dict[str, str]: ...
    @property
    def train_returns(self) -> list[float]: ...
    @property
    def factor_sizes(self) -> list[int]: ...
    def controller(self, method: str = "scaled", map: str = "jaywalk", **params: Any) -> Controller:
        """A fresh controller of ``method`` (``q-learning``, ``bayes-rl``, ``scaled``, the
        ablations, ``brake-on-pedestrian``, ``never-brake``) for episodes on ``map`` (the
        scripted ``brake-on-pedestrian`` follows its red-light rule); ``params`` are
        ``--set`` keys."""

@final
class Controller:
    """One method's controller."""

    @property
    def name(self) -> str: ...
    def begin_episode(self, seed: int) -> None: ...
    def act(self, observation: int | Sequence[int] | npt.NDArray[np.int64]) -> tuple[int, dict[str, Any]]:
        """``(action, decision)``; the decision has ``action``, ``reasoned``, ``surprise``,
        ``theta``, ``policy``, ``psi`` and ``scaling_iters``."""
    def observe(
        self, reward: float, next_observation: int | Sequence[int] | npt.NDArray[np.int64], terminated: bool, truncated: bool
    ) -> None: ...
    def end_episode(self) -> None:
        """Ends the episode; the scaled agent's test-time learning runs here."""

def train(map: str | os.PathLike[str], episodes: int, seed: int) -> Agent: ...
def load_agent(path: str) -> Agent: ...
def train_agents(
    seeds: Iterable[int],
    map: str | os.PathLike[str],
    episodes: int,
    cache: str | os.PathLike[str] | None,
    timeout_as: str,
) -> list[Agent]: ...
def scripted_controller(method: str, map: str = "jaywalk") -> Controller: ...
def eval_seeds(seed: int, map: str | os.PathLike[str], method: str, episode: int) -> tuple[int, int]:
    """``(world, controller)`` seeds of evaluation episode ``episode`` of the method named
    ``method`` (a built-in method's name, or the name a Python policy's lines carry)."""
def evaluate_policy(
    policy: Any,
    map: str | os.PathLike[str],
    method: str,
    protocols: Sequence[str],
    episodes: int,
    seed: int,
    train_seed: int | None = None,
    train_episodes: int | None = None,
    first_unit: int = 0,
    observation: str = "discrete",
) -> list[PolicyRun]:
    """Evaluates a Python policy (``act(obs) -> action`` or a callable, optional
    ``reset(seed)``; observations of form ``observation``) or a :class:`ScaledHabitAgent`
    (built with ``habit=`` or a habit table) on ``map`` by the library's episode loop,
    which calls it each tick with the GIL taken for the call only: a :class:`PolicyRun`
    per run, one per protocol for a wrapper that learns, else one covering them all;
    lines numbered from ``first_unit``, episodes of the method named ``method``. The
    policy's exceptions (and ``KeyboardInterrupt``) propagate."""

def scenario_sources(maps: Sequence[str | os.PathLike[str]]) -> list[tuple[str, str]]:
    """``(name, source)`` of each map's scenario as the batch's lines carry them
    (``("jaywalk", "embedded:jaywalk")``); a map listed twice is a ``ValueError``."""

@final
class PolicyRun:
    """One run of :func:`evaluate_policy`: its result line and its episodes."""

    @property
    def line(self) -> dict[str, Any]:
        """The result line (the batch results schema)."""
    @property
    def line_text(self) -> str:
        """The line as the results file holds it (the bytes ``unforeseen batch`` writes)."""
    @property
    def episodes(self) -> list[dict[str, Any]]:
        """Every episode, in order, as eval.json holds them."""
def evaluate(request: dict[str, Any], agent: Agent | None = None) -> EvalResult:
    """``unforeseen eval`` in this process: the eval request (its fields, as
    :func:`unforeseen.evaluate_builtin` takes them) planned and run by the library as the
    command line runs it, writing eval.json into its ``out``; ``agent`` is an agent
    given loaded instead of the request's agent file. A bad field raises ``ValueError``
    naming it."""
def compare(request: dict[str, Any], agents: Agent | Sequence[Agent] | None = None) -> CompareResult:
    """``unforeseen compare`` in this process: the compare request (its fields, as
    :func:`unforeseen.compare` takes them) planned, trained and run by the library
    as the command line runs it, writing its four files into its ``out``; ``agents`` are
    agents given loaded. A bad field raises ``ValueError`` naming it."""
def batch(request: dict[str, Any], agent: Agent | None = None) -> BatchResult:
    """``unforeseen batch`` in this process: the batch request (its fields, as
    :func:`unforeseen.batch` takes them), planned, trained and run by the library as the
    command line runs it, writing its results file and summary; ``agent`` is an agent
    given loaded instead of the request's agent file. A bad field raises ``ValueError``
    naming it."""
def request_defaults(job: str) -> str:
    """The fields of the request of ``job`` (``"batch"``, ``"search"``, ``"compare"``,
    ``"eval"`` or ``"estimate"``) with their defaults (JSON text)."""
def batch_result(lines: str) -> BatchResult:
    """The report of result lines (the JSON text of their list) that ``evaluate`` wrote,
    summarized and printed as ``unforeseen batch`` does its own."""

@final
class CompareResult:
    """``compare``'s report: compare.json's data; ``str()`` is the tables ``compare``
    prints (one per protocol). Rows: one per (protocol, method)."""

    def __str__(self) -> str:
        """The table the command line prints (also ``repr()``)."""
    def _repr_markdown_(self) -> str:
        """The table as Markdown (a notebook's rich display)."""
    def _repr_html_(self) -> str:
        """The table as an HTML fragment (a notebook's rich display)."""
    def __getitem__(self, key: str) -> Any:
        """The data under ``key`` (as ``to_dict()[key]``); ``KeyError`` if there is none."""
    def __contains__(self, key: str) -> bool: ...
    def keys(self) -> list[str]:
        """The data's keys, sorted."""
    def get(self, key: str, default: Any = None) -> Any: ...
    def to_dict(self) -> dict[str, Any]:
        """The whole data as a new dict (what ``json.load`` of the file gives)."""
    def to_records(self) -> list[dict[str, Any]]:
        """The table's rows as flat dicts: nested fields as ``outer_inner``, a summarized
        figure's mean under the figure's name (``success_rate``, ``success_rate_ci95_low``,
        ...)."""
    def to_pandas(self) -> Any:
        """``to_records()`` as a ``pandas.DataFrame``; ``ImportError`` naming the
        ``pandas`` extra where pandas is not installed."""
    @property
    def tables(self) -> list[dict[str, Any]]:
        """One table per protocol, each with its ``methods`` rows."""
    @property
    def protocols(self) -> list[str]: ...
    @property
    def train_map(self) -> str: ...
    @property
    def test_map(self) -> str: ...

@final
class EvalResult:
    """``eval``'s report: eval.json's data; ``str()`` is the line ``eval`` prints. Rows:
    one per episode."""

    def __str__(self) -> str:
        """The table the command line prints (also ``repr()``)."""
    def _repr_markdown_(self) -> str:
        """The table as Markdown (a notebook's rich display)."""
    def _repr_html_(self) -> str:
        """The table as an HTML fragment (a notebook's rich display)."""
    def __getitem__(self, key: str) -> Any:
        """The data under ``key`` (as ``to_dict()[key]``); ``KeyError`` if there is none."""
    def __contains__(self, key: str) -> bool: ...
    def keys(self) -> list[str]:
        """The data's keys, sorted."""
    def get(self, key: str, default: Any = None) -> Any: ...
    def to_dict(self) -> dict[str, Any]:
        """The whole data as a new dict (what ``json.load`` of the file gives)."""
    def to_records(self) -> list[dict[str, Any]]:
        """The table's rows as flat dicts: nested fields as ``outer_inner``, a summarized
        figure's mean under the figure's name (``success_rate``, ``success_rate_ci95_low``,
        ...)."""
    def to_pandas(self) -> Any:
        """``to_records()`` as a ``pandas.DataFrame``; ``ImportError`` naming the
        ``pandas`` extra where pandas is not installed."""
    @property
    def aggregate(self) -> dict[str, Any]:
        """The figures over every episode."""
    @property
    def episodes(self) -> list[dict[str, Any]]:
        """Every episode, in order."""

@final
class BatchResult:
    """``batch``'s report: the results file's ``lines`` and the ``summary`` over training
    seeds; ``str()`` is the summary table ``batch`` prints. Rows: one per summary row."""

    def __str__(self) -> str:
        """The table the command line prints (also ``repr()``)."""
    def _repr_markdown_(self) -> str:
        """The table as Markdown (a notebook's rich display)."""
    def _repr_html_(self) -> str:
        """The table as an HTML fragment (a notebook's rich display)."""
    def __getitem__(self, key: str) -> Any:
        """The data under ``key`` (as ``to_dict()[key]``); ``KeyError`` if there is none."""
    def __contains__(self, key: str) -> bool: ...
    def keys(self) -> list[str]:
        """The data's keys, sorted."""
    def get(self, key: str, default: Any = None) -> Any: ...
    def to_dict(self) -> dict[str, Any]:
        """The whole data as a new dict (what ``json.load`` of the file gives)."""
    def to_records(self) -> list[dict[str, Any]]:
        """The table's rows as flat dicts: nested fields as ``outer_inner``, a summarized
        figure's mean under the figure's name (``success_rate``, ``success_rate_ci95_low``,
        ...)."""
    def to_pandas(self) -> Any:
        """``to_records()`` as a ``pandas.DataFrame``; ``ImportError`` naming the
        ``pandas`` extra where pandas is not installed."""
    @property
    def lines(self) -> list[dict[str, Any]]:
        """The result lines, one per unit."""
    @property
    def checked(self) -> int:
        """The expectations checked on the mean over training seeds."""
    @property
    def failures(self) -> list[str]:
        """One message per expectation failed on the mean over training seeds."""
    @property
    def summary(self) -> list[dict[str, Any]]:
        """The summary's rows over training seeds."""

@final
class ScaledHabitAgent:
    """The scaled agent of ``agent`` around a habit: ``habit_table`` (``(n_states,
    n_actions)`` probabilities per state) or, without one, an external habit: the
    probabilities given to ``act`` each tick, and ``habit`` (``probs(obs)`` or a callable
    ``obs -> probabilities``, observations of form ``observation``), which
    :func:`evaluate_policy` asks each tick (``unforeseen_agent::habit``)."""

    def __init__(
        self,
        agent: Agent,
        habit_table: npt.NDArray[np.float64] | None = None,
        habit: Any = None,
        observation: str = "discrete",
        **params: Any,
    ) -> None: ...
    @property
    def external(self) -> bool: ...
    @property
    def observation(self) -> str: ...
    @property
    def learns(self) -> bool: ...
    def begin_episode(self, seed: int) -> None: ...
    def act(
        self, observed: int | Sequence[int], probs: npt.NDArray[np.float64] | None = None
    ) -> tuple[int, dict[str, Any]]: ...
    def observe(self, reward: float, next_observed: int | Sequence[int], terminated: bool, truncated: bool) -> None: ...
    def end_episode(self) -> None: ...
    def habit_counts(self) -> npt.NDArray[np.float64]:
        """Corrections learning added to an external habit (a table's counts ``ν``)."""

def q_table_habit(agent: Agent, **params: Any) -> npt.NDArray[np.float64]:
    """``σ(Q[s, ·]/T)`` of ``agent``'s Q-table, ``(n_states, n_actions)``."""
class ResultsGuard:
    def __init__(self, out: str, inputs: list[str], force: bool = False, append: bool = False) -> None: ...
    def release(self) -> None: ...

def summarize_json(path: str, partial: bool = False) -> str:
    """The batch summary over training seeds of a results file, as JSON text (a partial
    run refused unless ``partial``)."""
def check_batch(request: dict[str, Any], agent: Agent | None = None) -> None:
    """The batch request checked as :func:`plan_batch` checks it, without its output guard."""
def plan_batch(request: dict[str, Any], agent: Agent | None = None) -> str:
    """The batch request (its fields) planned as ``unforeseen batch`` plans it
    (JSON text: spec, head, total, kept, todo, todo_seeds, train_seeds_to_run, train,
    agent); passes the output guard, runs and trains nothing."""
def train_agent(seed: int, episodes: int, train_map: str = "intersection", timeout_as: str = "truncation") -> bytes:
    """The agent of one training seed (agent-file text), trained on ``train_map`` with the GIL released."""
def run_units(spec: str, agents: Sequence[tuple[int | None, bytes]], units: Sequence[int], threads: int = 1) -> list[str]:
    """The result lines (JSON text) of units of a planned run, with the GIL released."""
def finish_batch(out: str) -> BatchResult:
    """Rewrites a driver's results file in canonical order with its summary; its report,
    as :func:`unforeseen.batch` returns it."""
def plan_search(request: dict[str, Any], agent: Agent | None = None) -> str:
    """The search request (its fields) checked as ``unforeseen search`` checks
    it (arguments, base map, space file), before any task; JSON text of ``spec`` (the
    request), ``train`` (training seeds to train), ``train_map`` (where a node finds the
    training map), ``train_episodes``, ``timeout_as`` and ``agent`` (the given agent's
    text, or null)."""
def search(request: dict[str, Any], agent: Agent | None = None, command: str = "") -> str:
    """``unforeseen search`` in this process: the search request (its fields) planned, trained and run by the library as the command line runs it, writing
    its folder of outputs; ``summary.json``'s contents (JSON text). A bad field raises
    ``ValueError`` naming it; Ctrl-C raises KeyboardInterrupt at the next episode."""
def estimate(request: dict[str, Any]) -> str:
    """``unforeseen estimate`` in this process: the estimate request (its fields) planned,
    trained and run by the library as the command line runs it, writing ``estimate.jsonl``
    and ``summary.json`` (``resume`` keeping the draws of the same request in its folder;
    a ``shard`` writing ``estimate.jsonl`` alone); ``summary.json``'s contents, or a shard's
    part (JSON text). A bad field raises ``ValueError`` naming it; Ctrl-C raises
    KeyboardInterrupt at the next episode."""
def plan_estimate(request: dict[str, Any]) -> str:
    """The estimate request (its fields) checked as ``unforeseen estimate`` checks it,
    writing nothing; JSON text of ``spec`` (the request), ``search_spec`` (the search
    request whose candidates are the draws), ``train``, ``train_map``, ``train_episodes``,
    ``timeout_as`` and ``agent`` (the agent file's text, or null)."""
def drive_estimate(
    spec: str,
    agents: Sequence[tuple[int | None, bytes]],
    evaluate: Callable[[list[str]], list[list[str]]],
    stop: Any | None = None,
) -> str:
    """Runs an estimate's stages in Rust (the request ``spec`` from :func:`plan_estimate`,
    into its folder, from the draws left there with its ``resume``), each block of draws
    evaluated by ``evaluate`` (candidate JSON texts of ``search_spec``'s search -> each
    one's lines); ``summary.json``'s contents."""
def evaluate_search_candidates(
    spec: str,
    agents: Sequence[tuple[int | None, bytes]],
    candidates: Sequence[str],
    from_file: bool = False,
    threads: int = 1,
) -> list[list[str]]:
    """The candidate lines (JSON text) of a block of candidates, with the GIL released; Ctrl-C raises
    KeyboardInterrupt at the next episode."""
def drive_search(
    spec: str,
    agents: Sequence[tuple[int | None, bytes]],
    evaluate: Callable[[list[str]], list[list[str]]],
    from_file: bool = False,
    jobs: int = 1,
    command: str = "",
    stop: Any | None = None,
) -> str:
    """Runs a search's stages in Rust (the request ``spec`` from :func:`plan_search`, into
    its ``out``) with ``evaluate`` for its candidates; the summary (JSON text).
    Ctrl-C raises KeyboardInterrupt, calling ``stop.set()`` so an ``evaluate`` under way can return early."""

@final
class AifAgent:
    """A model in pymdp's layout behind the paper's surprise gate (the library's
    ``aif::gate::GatedAgent``); the pymdp-style front is :class:`unforeseen.aif.Agent`.
    Every bad array raises ``ValueError`` naming it."""

    def __init__(
        self,
        A: list[npt.NDArray[np.float64]],
        B: list[npt.NDArray[np.float64]],
        C: list[npt.NDArray[np.float64]] | None,
        D: list[npt.NDArray[np.float64]] | None,
        E: npt.NDArray[np.float64] | None,
        pA: list[npt.NDArray[np.float64]] | None,
        pB: list[npt.NDArray[np.float64]] | None,
        A_dependencies: list[list[int]] | None,
        B_dependencies: list[list[int]] | None,
        policies: list[list[list[int]]] | None,
        policy_len: int,
        gamma: float,
        alpha: float,
        num_iter: int,
        action_selection: str,
        sampling_mode: str,
        use_utility: bool,
        use_states_info_gain: bool,
        use_param_info_gain: bool,
        preferences: str,
        epsilon: float,
        habit_name: str,
        seed: int,
    ) -> None: ...
    def infer_states(
        self, observation: Sequence[int], empirical_prior: list[npt.NDArray[np.float64]] | None = None
    ) -> list[npt.NDArray[np.float64]]:
        """The posterior over each factor (pymdp's fpi), from ``empirical_prior`` (default D)."""
    def vfe(
        self,
        observation: Sequence[int],
        empirical_prior: list[npt.NDArray[np.float64]],
        qs: list[npt.NDArray[np.float64]],
    ) -> float:
        """The variational free energy of ``qs``, nats."""
    def infer_policies(
        self, qs: list[npt.NDArray[np.float64]]
    ) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
        """``(q_pi, neg_efe)`` of every policy (pymdp's order and sign)."""
    def sample_action(self, q_pi: npt.NDArray[np.float64]) -> npt.NDArray[np.int64]:
        """The action, one control per factor."""
    def update_empirical_prior(
        self, action: Sequence[int], qs: list[npt.NDArray[np.float64]]
    ) -> list[npt.NDArray[np.float64]]:
        """The prior of the next step after ``action``."""
    def infer_parameters(
        self,
        beliefs: list[list[list[float]]],
        observations: list[list[int]],
        actions: list[list[int]],
        lr_pA: float | None,
        lr_pB: float | None,
    ) -> None:
        """Dirichlet learning from one sequence (``beliefs[t][f]``, ``observations[t][m]``, ``actions[t][f]``)."""
    def step(
        self,
        observation: Sequence[int],
        habit: Callable[[list[int], list[npt.NDArray[np.float64]]], Any] | None = None,
    ) -> tuple[npt.NDArray[np.int64], dict[str, Any]]:
        """One gated tick: the action and ``surprise`` (bits), ``planned``, ``q_pi`` (when planned), ``qs``;
        with ``habit`` (``(observation, qs) -> action``) that policy acts when the gate is closed."""
    @property
    def epsilon(self) -> float:
        """ε in bits (negative: plan on every tick); settable, the learned habit kept."""
    @epsilon.setter
    def epsilon(self, value: float) -> None: ...
    def reset(self) -> None:
        """Start an episode (prior D; the learned habit kept)."""
    def utility(self, observation: Sequence[int]) -> float:
        """``Σ_m C[m][o_m]``."""
    def arrays(self, name: str) -> list[npt.NDArray[np.float64]] | None:
        """``A``, ``B``, ``C``, ``pA`` or ``pB`` (None when absent)."""
    @property
    def D(self) -> list[npt.NDArray[np.float64]]: ...
    @property
    def E(self) -> npt.NDArray[np.float64] | None: ...
    @property
    def policies(self) -> list[list[list[int]]]: ...
    @property
    def num_states(self) -> list[int]: ...
    @property
    def num_obs(self) -> list[int]: ...
    @property
    def num_controls(self) -> list[int]: ...
    @property
    def A_dependencies(self) -> list[list[int]]: ...
    @property
    def B_dependencies(self) -> list[list[int]]: ...
    @property
    def policy_len(self) -> int: ...

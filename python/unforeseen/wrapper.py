"""The scaled agent as a test-time safety layer around any policy.

:class:`ScaledWrapper` keeps the world model, the surprise gate, reasoning (VMP
perception, expected-free-energy planning), scaling and test-time learning of an agent
file's scaled agent, and takes the habit ``π_o`` from the given policy each tick. All of
it runs in Rust (``unforeseen_agent::habit``, ``unforeseen_agent::scaled``).

How learning combines with an external policy: reasoning's consolidation adds counts
``c[s, u]`` per discrete state ``s`` (from zero), and the habit in state ``s`` is

    π_o(u | s) = (ν0 p(u | obs) + c[s, u]) / (ν0 + Σ_u c[s, u])

with ``p`` the policy's probabilities at this tick's observation and ``ν0`` the
parameter ``nu0`` (10 by default). With no corrections the habit is the policy; where
reasoning kept choosing another action, the habit follows it.
"""

from __future__ import annotations

import difflib
import os
from typing import Any, Callable

import numpy as np

from . import _unforeseen

__all__ = ["ScaledWrapper", "q_table_habit"]

#: The keyword arguments of :class:`ScaledWrapper` that are not the agent's parameters.
_OWN_KEYWORDS = ("habit", "agent", "observation", "method")


def q_table_habit(agent: Any, **params: Any) -> np.ndarray:
    """The Q-table's habit of ``agent`` as per-state probabilities ``σ(Q[s, ·]/T)``,
    ``(n_states, n_actions)``, computed as the scaled agent computes them (``T`` is the
    parameter ``nu_temperature``)."""
    return _unforeseen.q_table_habit(_agent(agent), **params)


def _agent(agent: Any) -> Any:
    if isinstance(agent, (str, os.PathLike)):
        return _unforeseen.load_agent(agent)
    if isinstance(agent, _unforeseen.Agent):
        return agent
    raise TypeError(f"agent: expected an Agent or an agent file's path, got {type(agent).__name__}")


class ScaledWrapper:
    """The scaled agent of ``agent`` (an :class:`unforeseen.Agent` or an agent file) with
    the habit ``habit``:

    * a policy with ``probs(obs) -> probabilities`` (e.g. a deep baseline of
      :mod:`unforeseen.baselines`), or a callable ``obs -> probabilities``, asked each tick
      with the env's observation (its form is ``observation``, or the habit's
      ``observation`` attribute); its optional ``reset(seed)`` is called at the start of
      every episode (the policy protocol of :mod:`unforeseen.evaluate`);
    * an ``(n_states, n_actions)`` array of probabilities per discrete state (e.g.
      :func:`q_table_habit`);
    * ``None``: the agent's own Q-table habit (the built-in scaled agent).

    Keywords are the scaled agent's parameters (the keys of ``unforeseen eval --set``).
    :func:`unforeseen.evaluate` and :func:`unforeseen.evaluate.evaluate_policy` evaluate
    it by the library's episode loop, which asks the habit each tick (every run starts
    from the agent as built). To drive it step by step instead: :meth:`begin_episode`,
    :meth:`act` and :meth:`observe` with the env's ``info`` (the agent reads the observed
    discrete state ``info["observed"]``), :meth:`end_episode`.
    """

    def __init__(
        self,
        habit: Callable[[Any], Any] | np.ndarray | None = None,
        agent: Any = None,
        observation: str | None = None,
        method: str | None = None,
        **params: Any,
    ) -> None:
        for key in params:
            near = difflib.get_close_matches(key, _OWN_KEYWORDS, n=1)
            if near:
                raise TypeError(
                    f"ScaledWrapper() got an unexpected keyword argument {key!r}; did you mean {near[0]!r}? "
                    "(the other keywords are the scaled agent's parameters, the keys of --set)"
                )
        if agent is None:
            raise TypeError("ScaledWrapper needs agent=: an Agent or an agent file")
        self._agent = _agent(agent)
        self._params = params
        if habit is None:
            habit = q_table_habit(self._agent, **params)
        self._table: np.ndarray | None = None
        self._habit: Any = None
        self._probs: Callable[[Any], Any] | None = None
        if isinstance(habit, np.ndarray):
            if habit.ndim != 2:
                n_states = int(np.prod(self._agent.factor_sizes))
                raise ValueError(
                    f"habit: an array of shape {habit.shape}; a habit table is (n_states, n_actions) = "
                    f"({n_states}, 3), one row of action probabilities per state"
                )
            self._table = np.ascontiguousarray(habit, dtype=np.float64)
        elif hasattr(habit, "probs") and callable(habit.probs):
            self._habit, self._probs = habit, habit.probs
        elif callable(habit):
            self._habit, self._probs = habit, habit
        else:
            raise TypeError(
                f"habit: expected a callable obs -> probabilities, an object with probs(obs), "
                f"an (n_states, n_actions) array or None, got {type(habit).__name__}"
            )
        self.observation = observation or getattr(habit, "observation", None) or "discrete"
        if self.observation not in ("discrete", "kinematic"):
            raise ValueError(f"observation {self.observation!r}: expected 'discrete' or 'kinematic'")
        inner = getattr(habit, "method", None)
        self.method = method or (f"scaled+{inner}" if inner else "scaled-wrapper")
        self._inner = self._build()
        #: Whether test-time learning carries over between episodes (the parameter
        #: ``learning``), as the Rust library reads the parameters.
        self.learns = bool(self._inner.learns)

    def _build(self) -> Any:
        return _unforeseen.ScaledHabitAgent(self._agent, self._table, self._habit, self.observation, **self._params)

    def reset_learning(self) -> None:
        """Forget everything learned at test time while driven step by step (a fresh agent)."""
        self._inner = self._build()

    def begin_episode(self, seed: int) -> None:
        """Starts an episode driven step by step; ``seed`` seeds the agent's own sampling."""
        self._inner.begin_episode(seed)

    def act(self, obs: Any, info: dict[str, Any]) -> tuple[int, dict[str, Any]]:
        """``(action, decision)`` for the env's ``obs`` and ``info`` (step by step); the
        decision as :meth:`unforeseen.Controller.act` gives it."""
        if self._probs is None:
            return self._inner.act(info["observed"])
        p = np.asarray(self._probs(obs), dtype=np.float64).reshape(-1)
        return self._inner.act(info["observed"], p)

    def observe(self, reward: float, obs: Any, info: dict[str, Any], terminated: bool, truncated: bool) -> None:
        """The outcome of the last action (step by step)."""
        self._inner.observe(float(reward), info["observed"], bool(terminated), bool(truncated))

    def end_episode(self) -> None:
        """Test-time learning (the habit's corrections included), step by step."""
        self._inner.end_episode()

    def habit_counts(self) -> np.ndarray:
        """The corrections learning added to an external habit while driven step by step,
        ``(n_states, n_actions)`` (for a habit table: its counts ``ν``)."""
        return self._inner.habit_counts()

    def __repr__(self) -> str:
        return f"ScaledWrapper(method={self.method!r}, observation={self.observation!r})"

"""Any discrete active-inference model in pymdp's layout, behind the paper's surprise gate
(issue 46; the Rust library's ``unforeseen_agent::aif``).

``Agent(A, B, C, D, ...)`` takes pymdp's arguments and array layouts (``A[m][o, s...]``,
``B[f][s', s..., u]``, ``C`` as log-preferences, ``E`` over policies, Dirichlet ``pA``,
``pB``) as numpy arrays (or anything ``numpy.asarray`` takes), one model, no batch axis.
Its ``infer_states``, ``infer_policies``, ``sample_action``, ``update_empirical_prior``
and ``infer_parameters`` are pymdp's (``infer_policies`` returns ``(q_pi, neg_efe)``, the
sign pymdp returns); ``step(observation)`` runs the gated loop: it plans only when the
surprise (the VFE of the observation under its prediction, in bits) exceeds ``gate``,
and otherwise acts from its habit.

``Agent.from_pymdp(agent)`` converts a pymdp 1.0.4 agent (its first batch element), and
``rollout(agent, env, T)`` runs the gated loop in one of pymdp's environments through
their public ``reset``/``step``. Every check is the library's: a ragged, NaN or negative
array, an unnormalised column or a shape that does not fit its dependencies raises
``ValueError`` naming the array.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any, Union

import numpy as np

from ._unforeseen import AifAgent

__all__ = ["Agent", "Habit", "rollout"]

#: What ``step`` does when not surprised: ``"learned"``, ``"prior"``, or a policy
#: ``habit(observation, qs) -> action`` (one control index per factor, or an int for one
#: factor), asked with the observation (one index per modality) and the posterior.
Habit = Union[str, Callable[[list[int], list[np.ndarray]], Any]]


def _array(name: str, x: Any) -> np.ndarray:
    """``x`` as a float64 array, a ragged or non-numeric one refused naming ``name``."""
    try:
        a = np.asarray(x, dtype=np.float64)
    except (ValueError, TypeError) as e:
        raise ValueError(f"{name} is not a numeric array (ragged, or not numbers): {e}") from None
    return np.ascontiguousarray(a)


def _arrays(name: str, xs: Any) -> list[np.ndarray] | None:
    """A list of arrays (one per modality or factor), each named ``name[i]``."""
    if xs is None:
        return None
    if isinstance(xs, np.ndarray) and xs.dtype != object:
        raise ValueError(f"{name} must be a list of arrays, one per modality or factor (got one array)")
    return [_array(f"{name}[{i}]", x) for i, x in enumerate(xs)]


def _indices(name: str, xs: Any) -> list[int]:
    """Integer indices (an observation, an action), refused naming ``name``."""
    a = np.asarray(xs).reshape(-1)
    if a.dtype.kind == "f":
        if not np.all(np.isfinite(a)) or not np.all(a == np.round(a)):
            raise ValueError(f"{name} holds {a.tolist()}, must be whole numbers")
    elif a.dtype.kind not in "iu":
        raise ValueError(f"{name} holds {a.tolist()!r}, must be integer indices")
    return [int(v) for v in a]


def _marginals(name: str, qs: Any) -> list[np.ndarray]:
    return [_array(f"{name}[{f}]", q).reshape(-1) for f, q in enumerate(qs)]


class Agent:
    """pymdp's ``Agent`` on one model, with the paper's gate in ``step``.

    ``gate`` is ε in bits: ``step`` plans when the surprise exceeds it (``None`` or a
    negative value: on every tick, as pymdp). ``habit`` is what ``step`` does otherwise:
    ``"learned"`` (the action it planned most often before in the same most likely
    state; a state never planned in is planned in) or ``"prior"`` (``E``'s first-step
    marginal) or any Python policy ``habit(observation, qs) -> action`` (the
    ``ScaledWrapper`` pattern: it is asked only when the gate is closed, with the
    observation as a list of indices and the posterior ``qs``, one array per factor, and
    returns one control index per factor; planned actions still count toward the learned
    habit). ``preferences`` is ``"raw"`` (pymdp: ``C`` as given) or ``"ln_softmax"``
    (the paper). ``seed`` seeds stochastic action selection.
    """

    def __init__(
        self,
        A: Sequence[Any],
        B: Sequence[Any],
        C: Sequence[Any] | None = None,
        D: Sequence[Any] | None = None,
        E: Any | None = None,
        pA: Sequence[Any] | None = None,
        pB: Sequence[Any] | None = None,
        A_dependencies: Sequence[Sequence[int]] | None = None,
        B_dependencies: Sequence[Sequence[int]] | None = None,
        policies: Any | None = None,
        policy_len: int = 3,
        gamma: float = 1.0,
        alpha: float = 1.0,
        num_iter: int = 16,
        action_selection: str = "deterministic",
        sampling_mode: str = "full",
        use_utility: bool = True,
        use_states_info_gain: bool = True,
        use_param_info_gain: bool = False,
        preferences: str = "raw",
        gate: float | None = 1.0,
        habit: Habit = "learned",
        seed: int = 0,
    ) -> None:
        if isinstance(habit, str):
            self._habit: Callable[[list[int], list[np.ndarray]], Any] | None = None
            habit_name = habit
        elif callable(habit):
            self._habit, habit_name = habit, "learned"
        else:
            raise ValueError(
                f"habit is a {type(habit).__name__}, must be \"learned\", \"prior\" or a callable "
                "(observation, qs) -> action"
            )
        deps = lambda name, d: None if d is None else [_indices(f"{name}[{i}]", x) for i, x in enumerate(d)]  # noqa: E731
        pol = None
        if policies is not None:
            p = np.asarray(policies)
            if p.ndim != 3:
                raise ValueError(f"policies has shape {p.shape}, must be (num_policies, policy_len, num_factors)")
            pol = [[_indices(f"policies[{i}][{t}]", step) for t, step in enumerate(pi)] for i, pi in enumerate(p)]
        self._core = AifAgent(
            _arrays("A", A),
            _arrays("B", B),
            _arrays("C", C),
            _arrays("D", D),
            None if E is None else _array("E", E),
            _arrays("pA", pA),
            _arrays("pB", pB),
            deps("A_dependencies", A_dependencies),
            deps("B_dependencies", B_dependencies),
            pol,
            int(policy_len),
            float(gamma),
            float(alpha),
            int(num_iter),
            action_selection,
            sampling_mode,
            bool(use_utility),
            bool(use_states_info_gain),
            bool(use_param_info_gain),
            preferences,
            -1.0 if gate is None else float(gate),
            habit_name,
            int(seed),
        )

    @classmethod
    def from_pymdp(cls, agent: Any, gate: float | None = 1.0, habit: Habit = "learned", seed: int = 0) -> Agent:
        """This agent on a pymdp 1.0.4 ``Agent``'s model and settings (its first batch
        element; a batch of several is refused)."""
        if getattr(agent, "batch_size", 1) != 1:
            raise ValueError(f"the pymdp agent has batch_size {agent.batch_size}; convert one with batch_size=1")
        first = lambda xs: None if xs is None else [np.asarray(x)[0] for x in xs]  # noqa: E731
        E = getattr(agent, "E", None)
        return cls(
            first(agent.A),
            first(agent.B),
            C=first(agent.C),
            D=first(agent.D),
            E=None if E is None else np.asarray(E)[0],
            pA=first(agent.pA),
            pB=first(agent.pB),
            A_dependencies=agent.A_dependencies,
            B_dependencies=agent.B_dependencies,
            policies=np.asarray(agent.policies.policy_arr),
            policy_len=agent.policy_len,
            gamma=float(np.asarray(agent.gamma).reshape(-1)[0]),
            alpha=float(np.asarray(agent.alpha).reshape(-1)[0]),
            num_iter=agent.num_iter,
            action_selection=agent.action_selection,
            sampling_mode=agent.sampling_mode,
            use_utility=agent.use_utility,
            use_states_info_gain=agent.use_states_info_gain,
            use_param_info_gain=agent.use_param_info_gain,
            gate=gate,
            habit=habit,
            seed=seed,
        )

    @property
    def gate(self) -> float | None:
        """ε in bits (``None``: plan on every tick); settable, e.g. plan on every tick
        while the habit is learned, then gate; the learned habit is kept."""
        e = self._core.epsilon
        return None if e < 0 else e

    @gate.setter
    def gate(self, value: float | None) -> None:
        self._core.epsilon = -1.0 if value is None else float(value)

    # The model, as pymdp names it.
    @property
    def A(self) -> list[np.ndarray]:
        return self._core.arrays("A")

    @property
    def B(self) -> list[np.ndarray]:
        return self._core.arrays("B")

    @property
    def C(self) -> list[np.ndarray]:
        return self._core.arrays("C")

    @property
    def D(self) -> list[np.ndarray]:
        return self._core.D

    @property
    def E(self) -> np.ndarray | None:
        return self._core.E

    @property
    def pA(self) -> list[np.ndarray] | None:
        return self._core.arrays("pA")

    @property
    def pB(self) -> list[np.ndarray] | None:
        return self._core.arrays("pB")

    @property
    def A_dependencies(self) -> list[list[int]]:
        return self._core.A_dependencies

    @property
    def B_dependencies(self) -> list[list[int]]:
        return self._core.B_dependencies

    @property
    def policies(self) -> np.ndarray:
        return np.asarray(self._core.policies, dtype=np.int64)

    @property
    def policy_len(self) -> int:
        return self._core.policy_len

    @property
    def num_states(self) -> list[int]:
        return self._core.num_states

    @property
    def num_obs(self) -> list[int]:
        return self._core.num_obs

    @property
    def num_controls(self) -> list[int]:
        return self._core.num_controls

    # pymdp's loop.
    def infer_states(self, observations: Sequence[Any], empirical_prior: Sequence[Any] | None = None) -> list[np.ndarray]:
        """The posterior over each factor after ``observations`` (one index per
        modality) from ``empirical_prior`` (default ``D``): pymdp's fpi."""
        prior = None if empirical_prior is None else _marginals("empirical_prior", empirical_prior)
        return self._core.infer_states(_indices("observations", observations), prior)

    def vfe(self, observations: Sequence[Any], empirical_prior: Sequence[Any], qs: Sequence[Any]) -> float:
        """The variational free energy (nats) of ``qs`` (pymdp's ``info["vfe"]``)."""
        return self._core.vfe(
            _indices("observations", observations),
            _marginals("empirical_prior", empirical_prior),
            _marginals("qs", qs),
        )

    def infer_policies(self, qs: Sequence[Any]) -> tuple[np.ndarray, np.ndarray]:
        """``(q_pi, neg_efe)`` over ``self.policies`` (pymdp's order; ``neg_efe = −G``)."""
        return self._core.infer_policies(_marginals("qs", qs))

    def sample_action(self, q_pi: Any) -> np.ndarray:
        """The action, one control per factor, from ``q_pi``."""
        return self._core.sample_action(_array("q_pi", q_pi).reshape(-1))

    def update_empirical_prior(self, action: Any, qs: Sequence[Any]) -> list[np.ndarray]:
        """The prior of the next step after ``action`` from ``qs``."""
        return self._core.update_empirical_prior(_indices("action", action), _marginals("qs", qs))

    def infer_parameters(
        self,
        beliefs_A: Sequence[Any],
        observations: Sequence[Any],
        actions: Any,
        beliefs_B: Sequence[Any] | None = None,
        lr_pA: float = 1.0,
        lr_pB: float = 1.0,
    ) -> Agent:
        """pymdp's Dirichlet learning from one sequence, in place (returns ``self``, so
        pymdp's ``agent = agent.infer_parameters(...)`` works): ``beliefs_A[f]`` of
        shape ``(T, num_states[f])``, ``observations[m]`` of shape ``(T,)``, ``actions``
        of shape ``(T, num_factors)`` (the last is ignored). ``A`` is learned when the
        model has ``pA``, ``B`` when it has ``pB``."""
        beliefs = beliefs_A if beliefs_B is None else beliefs_B
        qs = [_array(f"beliefs_A[{f}]", b) for f, b in enumerate(beliefs)]
        for f, b in enumerate(qs):
            if b.ndim != 2:
                raise ValueError(f"beliefs_A[{f}] has shape {b.shape}, must be (T, num_states[{f}])")
        steps = qs[0].shape[0] if qs else 0
        per_t = [[q[t] for q in qs] for t in range(steps)]
        obs = [np.asarray(o).reshape(-1) for o in observations]
        if any(len(o) != steps for o in obs):
            raise ValueError(f"observations must hold {steps} steps per modality, as beliefs_A does")
        obs_t = [_indices(f"observations at t={t}", [o[t] for o in obs]) for t in range(steps)]
        acts = np.asarray(actions)
        if acts.ndim == 1:
            acts = acts.reshape(1, -1)
        acts_t = [_indices(f"actions[{t}]", u) for t, u in enumerate(acts)]
        has = self._core.arrays
        self._core.infer_parameters(
            [[b.tolist() for b in step] for step in per_t],
            obs_t,
            acts_t,
            float(lr_pA) if has("pA") is not None else None,
            float(lr_pB) if has("pB") is not None else None,
        )
        return self

    # The paper's gate.
    def reset(self) -> None:
        """Start an episode: the prior is ``D`` again (the learned habit is kept)."""
        self._core.reset()

    def step(self, observation: Sequence[Any]) -> tuple[np.ndarray, dict[str, Any]]:
        """One tick of the gated loop: ``(action, info)``; ``info`` holds ``surprise``
        (bits), ``planned``, ``q_pi`` (when planned) and ``qs``. A Python ``habit``
        is asked here when the gate is closed; its exceptions propagate."""
        return self._core.step(_indices("observation", observation), self._habit)

    def utility(self, observation: Sequence[Any]) -> float:
        """``Σ_m C[m][o_m]`` of ``observation`` (a time-indexed ``C``'s first row)."""
        return self._core.utility(_indices("observation", observation))


def rollout(agent: Agent, env: Any, T: int, seed: int = 0, learn: bool = False) -> dict[str, Any]:
    """The gated loop for ``T`` ticks in ``env``, one of pymdp's environments (anything
    with pymdp's ``reset(key) -> (obs, state)`` and ``step(key, state, action) -> (obs,
    state)``), JAX keys from ``seed``. With ``learn``, ``infer_parameters`` from the
    episode at its end. Returns numpy arrays: ``observation`` (T, modalities),
    ``action`` (T, factors), ``planned`` (T,), ``surprise`` (T,, bits), ``utility``
    (T,), and ``planned_fraction``, ``return``."""
    import jax
    import jax.numpy as jnp

    if int(T) < 1:
        raise ValueError(f"T is {T}, must be at least 1")
    key = jax.random.PRNGKey(int(seed))
    key, k = jax.random.split(key)
    obs, state = env.reset(k)
    agent.reset()
    rows: dict[str, list[Any]] = {"observation": [], "action": [], "planned": [], "surprise": [], "utility": []}
    beliefs: list[list[np.ndarray]] = []
    for _ in range(int(T)):
        o = [int(np.asarray(x).reshape(-1)[0]) for x in obs]
        action, info = agent.step(o)
        rows["observation"].append(o)
        rows["action"].append(action)
        rows["planned"].append(info["planned"])
        rows["surprise"].append(info["surprise"])
        rows["utility"].append(agent.utility(o))
        beliefs.append(info["qs"])
        key, k = jax.random.split(key)
        obs, state = env.step(k, state, jnp.asarray(action))
    out: dict[str, Any] = {
        "observation": np.asarray(rows["observation"], dtype=np.int64),
        "action": np.asarray(rows["action"], dtype=np.int64),
        "planned": np.asarray(rows["planned"], dtype=bool),
        "surprise": np.asarray(rows["surprise"], dtype=np.float64),
        "utility": np.asarray(rows["utility"], dtype=np.float64),
    }
    if learn:
        per_factor = [np.stack([b[f] for b in beliefs]) for f in range(len(agent.num_states))]
        agent.infer_parameters(per_factor, list(out["observation"].T), out["action"])
    out["planned_fraction"] = float(out["planned"].mean())
    out["return"] = float(out["utility"].sum())
    return out

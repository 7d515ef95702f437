"""Bring your own model: a pymdp T-maze agent behind the paper's surprise gate.

    pip install './python[pymdp]'                 # unforeseen with pymdp 1.0.4 (JAX)
    python examples/pymdp_tmaze.py                # full sizes: about a minute
    UNFORESEEN_EXAMPLE_SMALL=1 python examples/pymdp_tmaze.py   # what CI runs: seconds

1. A pymdp 1.0.4 ``Agent`` on pymdp's own T-maze (its A, B, D; reward preferred,
   punishment avoided; Dirichlet counts pA, pB so that it can learn).
2. ``unforeseen.aif.Agent.from_pymdp`` converts it: the same arrays and settings, and
   the same beliefs and policy posterior (checked on the first observation).
3. Training: episodes in the T-maze planning on every tick, as pymdp's loop does; the
   gated agent's habit (the action it planned most often in each most likely state) is
   learned here.
4. Test: the gate at ε = 1 bit (plan only when surprised, otherwise act from the habit),
   with the learned habit and with a Python policy as the habit (go to the cue until the
   reward condition is known, then to its arm), beside planning on every tick, in the
   T-maze as trained and in one whose cue points to the wrong arm 95 % of the time (an
   unforeseen change); all learn pA, pB after each episode. Prints the fraction of ticks
   planned and the return per episode of each.

In the T-maze the learned habit (the action planned most often in the most likely
state) keeps the agent at the cue, where nothing surprises it: the gate saves compute
but not return there (EXPERIMENTS.md, "The habit ablation"; the grid world with a wall
is where it pays).
"""

from __future__ import annotations

import os

import jax
import numpy as np

jax.config.update("jax_enable_x64", True)

import jax.numpy as jnp  # noqa: E402
from pymdp.agent import Agent as PymdpAgent  # noqa: E402
from pymdp.envs.tmaze import TMaze  # noqa: E402

from unforeseen.aif import Agent, rollout  # noqa: E402

SMALL = os.environ.get("UNFORESEEN_EXAMPLE_SMALL") == "1"
TRAIN_EPISODES = 3 if SMALL else 20
TEST_EPISODES = 3 if SMALL else 30
TICKS = 8 if SMALL else 10
SEED = 11
CENTRE, LEFT, RIGHT, CUE, MIDDLE = range(5)


def pymdp_agent(env: TMaze) -> PymdpAgent:
    """pymdp's agent on the env's model, with counts so that it can learn."""
    pA = [10.0 * a + 0.1 for a in env.A]
    pB = [10.0 * b + 0.1 for b in env.B]
    C = [jnp.zeros(a.shape[0]) for a in env.A]
    C[1] = jnp.array([0.0, 2.0, -4.0])  # no outcome, reward, punishment
    return PymdpAgent([p / p.sum(axis=0, keepdims=True) for p in pA], [p / p.sum(axis=0, keepdims=True) for p in pB],
                      C=C, D=env.D, pA=pA, pB=pB, A_dependencies=env.A_dependencies,
                      B_dependencies=env.B_dependencies, policy_len=3)


def cue_then_arm(observation: list[int], qs: list[np.ndarray]) -> list[int]:
    """A Python habit: to the cue while the reward condition is uncertain, then to its arm."""
    location = observation[0]
    if float(np.max(qs[1])) < 0.8:
        return [CUE if location in (CENTRE, CUE) else (MIDDLE if location in (LEFT, RIGHT) else CENTRE), 0]
    arm = LEFT + int(np.argmax(qs[1]))
    return [arm if location == arm else {CUE: CENTRE, CENTRE: MIDDLE, MIDDLE: arm}.get(location, MIDDLE), 0]


def trained(theirs: PymdpAgent, world: TMaze, habit) -> Agent:
    """Converted, then trained in ``world`` planning on every tick (habit and counts)."""
    agent = Agent.from_pymdp(theirs, gate=None, habit=habit)
    for e in range(TRAIN_EPISODES):
        rollout(agent, world, TICKS, seed=SEED * 1000 + e, learn=True)
    return agent


def main() -> None:
    world = TMaze()
    theirs = pymdp_agent(world)
    ours = Agent.from_pymdp(theirs, gate=None)
    first = [0, 0, 0]
    q_pi_theirs, _ = theirs.infer_policies(theirs.infer_states([jnp.array([o]) for o in first], theirs.D))
    q_pi, _ = ours.infer_policies(ours.infer_states(first))
    gap = float(np.abs(q_pi - np.asarray(q_pi_theirs)[0]).max())
    print(f"converted pymdp's T-maze agent: {len(ours.policies)} policies of {ours.policy_len} steps, "
          f"q_pi equal to pymdp's within {gap:.1e}")

    worlds = {"as trained": world, "cue lies": TMaze(cue_validity=0.05)}
    arms = [("plans every tick", None, "learned"), ("gated, learned habit", 1.0, "learned"),
            ("gated, Python habit", 1.0, cue_then_arm)]
    print(f"{'test world':<11} {'agent':<21} {'ticks planned':>13} {'return per episode':>19}")
    for name, test in worlds.items():
        for label, gate, habit in arms:
            agent = trained(theirs, world, habit)
            agent.gate = gate
            planned, returns = [], []
            for e in range(TEST_EPISODES):
                out = rollout(agent, test, TICKS, seed=SEED * 1000 + 500 + e, learn=True)
                planned.append(out["planned_fraction"])
                returns.append(out["return"])
            print(f"{name:<11} {label:<21} {np.mean(planned):>13.2f} {np.mean(returns):>19.2f}")


if __name__ == "__main__":
    main()

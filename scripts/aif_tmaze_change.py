#!/usr/bin/env python3
"""The gate on pymdp's T-maze when the cue starts to lie (issue 46), with the habit learned
in a training phase before the change, and the habit ablation.

pymdp 1.0.4's own ``TMaze()`` (5 locations: centre, left arm, right arm, cue, middle; the
reward condition drawn at each reset; the cue right 95 % of the time), stepped through its
public ``reset``/``step`` by ``unforeseen.aif.rollout``. The agent is
``unforeseen.aif.Agent`` on its A, B, D with C = [0, 2, −4] on the reward modality (no
outcome, reward, punishment), ``policy_len`` 3, γ = 1, counts pA = 10 A + 0.1 and
pB = 10 B + 0.1 (A, B their normalisation), learned after every episode.

The protocol and the arms are scripts/aif_gate_runs.py's: ``--train`` episodes in the
T-maze planning on every tick, then ``--test`` episodes in ``TMaze(cue_validity=0.05)``
(the cue points to the wrong arm 95 % of the time: the unforeseen change) and, as the
control, in the T-maze as trained. The Python policy habit is what a person who knows the
trained T-maze would write: while the posterior over the reward condition is below 0.8,
go to the cue (from the centre; stay there); once it is above, go to that condition's arm
through the centre and the middle, and stay. Return = Σ_t C[o_t]; success = a reward and
no punishment in the episode.

Usage (needs jax and pymdp):  python3 scripts/aif_tmaze_change.py --choose 1..10 --seeds 11..20
"""

from __future__ import annotations

import jax
import numpy as np

jax.config.update("jax_enable_x64", True)

from pymdp.envs.tmaze import TMaze  # noqa: E402

from aif_gate_runs import Setup, arguments, main  # noqa: E402
from unforeseen.aif import Agent  # noqa: E402

CENTRE, LEFT, RIGHT, CUE, MIDDLE = range(5)
#: The trained T-maze (one instance: pymdp jits reset/step per instance).
TRAINED = TMaze()


def make_agent(seed: int, habit, E=None, A=None, B=None, pA=None, pB=None) -> Agent:
    world = TRAINED
    if pA is None:
        pA = [10.0 * np.asarray(a) + 0.1 for a in world.A]
        pB = [10.0 * np.asarray(b) + 0.1 for b in world.B]
        A = [p / p.sum(axis=0, keepdims=True) for p in pA]
        B = [p / p.sum(axis=0, keepdims=True) for p in pB]
    C = [np.zeros(np.asarray(a).shape[0]) for a in world.A]
    C[1] = np.array([0.0, 2.0, -4.0])
    return Agent(A, B, C=C, D=[np.asarray(d) for d in world.D], E=E, pA=pA, pB=pB,
                 A_dependencies=world.A_dependencies, B_dependencies=world.B_dependencies,
                 policy_len=3, gate=None, habit=habit, seed=seed)


def policy(observation: list[int], qs: list[np.ndarray]) -> list[int]:
    """The trained T-maze's way: find out at the cue, then go to the cued arm and stay."""
    location = int(observation[0])
    condition = int(np.argmax(qs[1]))
    if float(np.max(qs[1])) < 0.8:
        return [CUE if location in (CENTRE, CUE) else (MIDDLE if location in (LEFT, RIGHT) else CENTRE), 0]
    arm = LEFT + condition
    if location == arm:
        return [arm, 0]
    return [{CUE: CENTRE, CENTRE: MIDDLE, MIDDLE: arm}.get(location, MIDDLE), 0]


def success(out) -> float:
    reward = out["observation"][:, 1]
    return float(np.any(reward == 1) and not np.any(reward == 2))


if __name__ == "__main__":
    args = arguments(__doc__, train=20, test=30, steps=10).parse_args()
    main(Setup(make_agent, TRAINED, {"cue lies": TMaze(cue_validity=0.05), "as trained": TRAINED}, "cue lies",
               policy, success), args)

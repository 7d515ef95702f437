#!/usr/bin/env python3
"""The gate on pymdp's grid world when a wall appears on the learned path (issue 46).

pymdp 1.0.4's own ``GridWorld`` (3x3, STAY included, random start over free cells; C = 3
at the goal, the last cell, as scripts/pymdp_envs_reference.py sets it), stepped through
its public ``reset``/``step`` by ``unforeseen.aif.rollout``. The agent is
``unforeseen.aif.Agent`` on the wall-free world's model (A, B, D of ``GridWorld()``),
``policy_len`` 4 (the farthest cell is 4 moves from the goal), counts ``pB = 5 B + 0.1``.

Per seed: ``--train`` episodes in the wall-free world planning on every tick (the habit:
counts on (most likely cell, planned action)), then ``--test`` episodes in
``GridWorld(walls=[(1, 2)])``: the wall on the path the trained agent takes from the top
row (right, right, down, down through cell 5). Every arm learns pB after each test
episode (test-time learning). Arms, by ε at test: ε < 0 plans on every tick (pymdp's
loop); ε ≥ 0 plans when the surprise exceeds ε bits; ε = 1e9 is the habit alone (it plans
only in a cell it never planned in). Return per test episode = Σ_t C[o_t]; success = the
goal reached within the episode.

With ``--ablation``, the habit ablation of scripts/aif_gate_runs.py instead (ε chosen per
habit on ``--choose`` seeds, then the report seeds): the habit learned in training, a given
``E``, or a Python policy written for the wall-free grid (right along the row, then down
the last column, then stay: the trained agent's path from the top row, into the wall).

Usage (needs jax and pymdp):  python3 scripts/aif_grid_wall.py --seeds 11..20 --figure docs/figures/aif_grid_wall.png
                              python3 scripts/aif_grid_wall.py --ablation --choose 1..10 --seeds 11..20
"""

from __future__ import annotations

import argparse
import statistics
import sys

import jax
import numpy as np

jax.config.update("jax_enable_x64", True)

from pymdp.envs.grid_world import GridWorld  # noqa: E402

import aif_gate_runs  # noqa: E402
from unforeseen.aif import Agent, rollout  # noqa: E402

WALL = (1, 2)


seeds, interval = aif_gate_runs.seeds, aif_gate_runs.interval


def make_agent(seed: int, habit="learned", E=None, A=None, B=None, pA=None, pB=None, world: GridWorld | None = None) -> Agent:
    world = world or GridWorld()
    if pB is None:
        A = [np.asarray(a) for a in world.A]
        pB = [5.0 * np.asarray(b) + 0.1 for b in world.B]
        B = [p / p.sum(axis=0, keepdims=True) for p in pB]
    C = [np.zeros(np.asarray(A[0]).shape[0])]
    C[0][-1] = 3.0
    return Agent(A, B, C=C, D=[np.asarray(d) for d in world.D], E=E, pA=pA, pB=pB,
                 A_dependencies=world.A_dependencies, B_dependencies=world.B_dependencies,
                 policy_len=4, gate=None, habit=habit, seed=seed)


def policy(observation: list[int], qs: list[np.ndarray]) -> int:
    """The wall-free grid's way to the goal: right along the row, down the last column."""
    row, col = divmod(int(observation[0]), 3)
    return GridWorld.RIGHT if col < 2 else (GridWorld.DOWN if row < 2 else GridWorld.STAY)


def run_seed(seed: int, eps: float, args, free: GridWorld, test_world: GridWorld) -> dict[str, float]:
    agent = make_agent(seed, world=free)
    for e in range(args.train):
        rollout(agent, free, args.steps, seed=seed * 1000 + e, learn=True)
    agent.gate = None if eps < 0 else eps
    rets, wins, planned = [], [], []
    goal = free.A[0].shape[0] - 1
    for e in range(args.test):
        out = rollout(agent, test_world, args.steps, seed=seed * 1000 + 500 + e, learn=True)
        rets.append(out["return"])
        wins.append(float(np.any(out["observation"][:, 0] == goal)))
        planned.append(out["planned_fraction"])
    return {"return": statistics.mean(rets), "success": statistics.mean(wins), "planned": statistics.mean(planned)}


def ablation() -> None:
    args = aif_gate_runs.arguments(__doc__, train=20, test=20, steps=8).parse_args(
        [a for a in sys.argv[1:] if a != "--ablation"])
    free, walled = GridWorld(), GridWorld(walls=[WALL])
    goal = free.A[0].shape[0] - 1
    aif_gate_runs.main(aif_gate_runs.Setup(
        lambda seed, **kw: make_agent(seed, world=free, **kw), free, {"wall": walled, "no wall": free}, "wall", policy,
        lambda out: float(np.any(out["observation"][:, 0] == goal))), args)


def main() -> None:
    if "--ablation" in sys.argv:
        ablation()
        return
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--seeds", default="11..20")
    ap.add_argument("--eps", default="-1,0.1,0.5,1,2,4,1e9")
    ap.add_argument("--train", type=int, default=20)
    ap.add_argument("--test", type=int, default=20)
    ap.add_argument("--steps", type=int, default=8)
    ap.add_argument("--figure", default=None, help="the figure of ticks planned against return as ε varies (PNG)")
    args = ap.parse_args()
    # One instance of each world: pymdp jits reset/step per instance.
    free, walled = GridWorld(), GridWorld(walls=[WALL])
    rows = []
    print("| test world | ε at test (bits) | return per test episode, mean [95%] | worst seed | success | ticks planned |")
    print("|---|---|---|---|---|---|")
    for world, eps_s in [(w, e) for w in ("wall", "no wall") for e in args.eps.split(",")]:
        eps = float(eps_s)
        test_world = walled if world == "wall" else free
        per = [run_seed(s, eps, args, free, test_world) for s in seeds(args.seeds)]
        r, rh = interval([p["return"] for p in per])
        w, wh = interval([p["success"] for p in per])
        pl, plh = interval([p["planned"] for p in per])
        worst = min(p["return"] for p in per)
        label = "every tick" if eps < 0 else ("habit alone" if eps >= 1e8 else eps_s)
        rows.append((world, label, r, rh, pl, plh))
        print(f"| {world} | {label} | {r:.2f} [{r - rh:.2f}, {r + rh:.2f}] | {worst:.2f} | {w:.2f} ± {wh:.2f} | {pl:.3f} ± {plh:.3f} |",
              flush=True)
    if args.figure:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(7, 4.5))
        for world, colour in [("wall", "tab:red"), ("no wall", "tab:blue")]:
            mine = [x for x in rows if x[0] == world]
            xs, ys = [x[4] for x in mine], [x[2] for x in mine]
            ax.errorbar(xs, ys, xerr=[x[5] for x in mine], yerr=[x[3] for x in mine], fmt="o-", capsize=3,
                        color=colour, label=f"test world: {world}")
            for i, (_, label, r, _, pl, _) in enumerate(mine):
                text = label if not label[0].isdigit() else f"ε={label}"
                ax.annotate(text, (pl, r), textcoords="offset points", xytext=(6, 8 if i % 2 else -12), fontsize=8,
                            color=colour)
        ax.legend(loc="lower right")
        ax.set_xlabel("fraction of ticks planned (compute)")
        ax.set_ylabel("return per test episode")
        ax.set_title(f"pymdp grid world, wall at {WALL} after training (seeds {args.seeds}, 95% CI)")
        fig.tight_layout()
        fig.savefig(args.figure, dpi=100)


if __name__ == "__main__":
    main()

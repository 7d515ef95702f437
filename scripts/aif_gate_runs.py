"""What scripts/aif_tmaze_change.py and scripts/aif_grid_wall.py share (issue 46): the
protocol of a gated agent on one of pymdp's environments with an unforeseen change at
test, and the habit ablation.

Per seed and arm: ``train`` episodes in the training world planning on every tick (pymdp's
loop), learning pA/pB after each; the learned habit (counts on (most likely state,
planned action)) is learned here, before the change. Then ``test`` episodes in a test
world, every arm learning after each episode (test-time learning), with ε at test and the
habit of the arm:

* ``learned``: the counts of the training phase (and of planned test ticks);
* ``prior``: a given ``E``, here the frequency of each policy the agent chose (argmax
  ``q_pi``) in the training phase plus one, normalised; it is the state-independent habit
  (``E``'s first-step marginal) and, as in pymdp, ``+ ln E`` in every ``q_pi``;
* ``policy``: a Python policy ``(observation, qs) -> action`` written for the training
  world (each script's ``policy``), the ``ScaledWrapper`` pattern.

ε < 0 plans on every tick; ε = 1e9 is the habit alone (the learned habit still plans in a
state it never planned in). ``--choose`` seeds pick ε per habit (the best mean return in
the changed world over a grid, ties to fewer ticks planned); the report seeds then run
the chosen ε, the habit alone and planning on every tick, in the changed world and the
unchanged one. Intervals are 95 % Student-t over seeds.
"""

from __future__ import annotations

import argparse
import math
import statistics
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from unforeseen.aif import Agent, rollout

T975 = {2: 12.71, 3: 4.30, 4: 3.18, 5: 2.78, 6: 2.57, 7: 2.45, 8: 2.36, 9: 2.31, 10: 2.26, 11: 2.23}
HABITS = ("learned", "prior", "policy")
ALONE = 1e9


def seeds(spec: str) -> list[int]:
    a, b = spec.split("..")
    return list(range(int(a), int(b) + 1))


def interval(xs: list[float]) -> tuple[float, float]:
    """Mean and the half-width of its 95 % t-interval."""
    m = statistics.mean(xs)
    h = T975.get(len(xs), 1.96) * statistics.stdev(xs) / math.sqrt(len(xs)) if len(xs) > 1 else float("nan")
    return m, h


@dataclass
class Setup:
    """One environment's experiment: how to build the agent, the worlds, the Python
    policy of the training world and what counts as success."""

    make_agent: Callable[..., Agent]
    train_world: Any
    worlds: dict[str, Any]
    changed: str
    policy: Callable[[list[int], list[np.ndarray]], Any]
    success: Callable[[dict[str, Any]], float]


def run_arm(setup: Setup, args: argparse.Namespace, seed: int, eps: float, habit: str, world: str) -> dict[str, float]:
    """Train (planning on every tick), then test with ``habit`` at ε; the per-episode means."""
    agent = setup.make_agent(seed, habit=setup.policy if habit == "policy" else "learned")
    chosen: dict[int, int] = {}
    step = agent.step

    def counting_step(observation: list[int]) -> tuple[np.ndarray, dict[str, Any]]:
        action, info = step(observation)
        if info["planned"]:
            p = int(np.argmax(info["q_pi"]))
            chosen[p] = chosen.get(p, 0) + 1
        return action, info

    agent.step = counting_step  # type: ignore[method-assign]
    for e in range(args.train):
        rollout(agent, setup.train_world, args.steps, seed=seed * 1000 + e, learn=True)
    if habit == "prior":
        E = np.ones(len(agent.policies))
        for p, n in chosen.items():
            E[p] += n
        agent = setup.make_agent(seed, habit="prior", E=E / E.sum(), A=agent.A, B=agent.B, pA=agent.pA, pB=agent.pB)
    else:
        agent.step = step  # type: ignore[method-assign]
    agent.gate = None if eps < 0 else eps
    rets, wins, planned = [], [], []
    for e in range(args.test):
        out = rollout(agent, setup.worlds[world], args.steps, seed=seed * 1000 + 500 + e, learn=True)
        rets.append(out["return"])
        wins.append(setup.success(out))
        planned.append(out["planned_fraction"])
    return {"return": statistics.mean(rets), "success": statistics.mean(wins), "planned": statistics.mean(planned)}


def arguments(description: str, train: int, test: int, steps: int) -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(description=description, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--choose", default="1..10", help="seeds that choose ε per habit")
    ap.add_argument("--seeds", default="11..20", help="seeds reported")
    ap.add_argument("--eps", default="0.25,0.5,1,2,4", help="the ε grid (bits) the choice runs")
    ap.add_argument("--habits", default=",".join(HABITS))
    ap.add_argument("--train", type=int, default=train)
    ap.add_argument("--test", type=int, default=test)
    ap.add_argument("--steps", type=int, default=steps)
    return ap


def main(setup: Setup, args: argparse.Namespace) -> list[tuple[str, str, float, float, float, float]]:
    """Choose ε per habit, then print the report's markdown table; returns its rows
    (world, arm, return, its half-width, ticks planned, its half-width)."""
    habits = args.habits.split(",")
    chosen: dict[str, float] = {}
    for habit in habits:
        best = None
        for eps_s in args.eps.split(","):
            per = [run_arm(setup, args, s, float(eps_s), habit, setup.changed) for s in seeds(args.choose)]
            key = (statistics.mean(p["return"] for p in per), -statistics.mean(p["planned"] for p in per))
            print(f"choose {habit}: ε={eps_s} return {key[0]:.3f}, ticks planned {-key[1]:.3f}", flush=True)
            if best is None or key > best[0]:
                best = (key, float(eps_s))
        chosen[habit] = best[1]
    print(f"\nε chosen on seeds {args.choose} ({setup.changed}, best mean return): {chosen}\n")
    print("| test world | habit | ε at test (bits) | return per test episode, mean [95%] | worst seed | success | ticks planned |")
    print("|---|---|---|---|---|---|---|")
    rows = []
    arms = [("—", -1.0)] + [(h, e) for h in habits for e in (chosen[h], ALONE)]
    for world in setup.worlds:
        for habit, eps in arms:
            per = [run_arm(setup, args, s, eps, "learned" if habit == "—" else habit, world) for s in seeds(args.seeds)]
            r, rh = interval([p["return"] for p in per])
            w, wh = interval([p["success"] for p in per])
            pl, plh = interval([p["planned"] for p in per])
            label = "every tick" if eps < 0 else ("habit alone" if eps >= ALONE else f"{eps:g}")
            rows.append((world, f"{habit} {label}", r, rh, pl, plh))
            worst = min(p["return"] for p in per)
            print(f"| {world} | {habit} | {label} | {r:.2f} [{r - rh:.2f}, {r + rh:.2f}] | {worst:.2f} | "
                  f"{w:.2f} ± {wh:.2f} | {pl:.3f} ± {plh:.3f} |", flush=True)
    return rows

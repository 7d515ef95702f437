#!/usr/bin/env python3
"""Per planning tick, ours (`unforeseen_agent::aif`) beside pymdp 1.0.4's fastest way to
drive it, on the models of pymdp's own environments (issue 46).

For each environment of agent/tests/data/pymdp/ (written by scripts/pymdp_envs_reference.py)
and each policy length asked for, on the stored rollout's 50 observations and actions
(the prior back to D at each reset), with the gate open (planning on every tick):

  * ours: `examples/aif_ticks.rs` (release build) replays the sequence, times each tick
    (infer_states + infer_policies + sample_action + update_empirical_prior) and prints
    the action it chose at every tick;
  * pymdp: the same tick inside one `jax.jit`-compiled `lax.scan` over the sequence
    (compile time excluded; no Python per tick), float32 and float64, each in its own
    process, CPU;

and prints one table: µs per tick (median over repetitions), the ratio of pymdp's fastest
to ours, and how many ticks chose the same action (an argmax between policies whose q_pi
agree to 1e-9 counts as a tie, reported apart).

Usage:  cargo build --release --example aif_ticks
        OMP_NUM_THREADS=1 taskset -c 1 python3 scripts/pymdp_envs_bench.py --lens 1,2,3,4,5
"""
import argparse
import json
import os
import subprocess
import sys
import time

import numpy as np

ENVS = ["tmaze", "generalized_tmaze", "grid_world", "cue_chaining"]
DATA = "agent/tests/data/pymdp"


def worker(args):
    import jax

    if args.dtype == "float64":
        jax.config.update("jax_enable_x64", True)
    import jax.numpy as jnp
    import jax.tree_util as jtu
    from jax import lax
    from pymdp.agent import Agent

    dt = jnp.float64 if args.dtype == "float64" else jnp.float32
    r = json.load(open(os.path.join(DATA, f"{args.env}.json")))
    m = r["model"]
    arr = lambda x: jnp.asarray(np.asarray(x, dtype=float), dtype=dt)
    agent = Agent([arr(a) for a in m["A"]], [arr(b) for b in m["B"]], C=[arr(c) for c in m["C"]],
                  D=[arr(d) for d in m["D"]], A_dependencies=m["A_dependencies"],
                  B_dependencies=m["B_dependencies"], policy_len=args.policy_len, gamma=m["gamma"])
    steps = r["rollout"]
    nm = len(m["A"])
    obs = jnp.asarray([s["obs"] for s in steps], dtype=jnp.int32)  # (T, M)
    acts = jnp.asarray([s["action"] for s in steps], dtype=jnp.int32)  # (T, F)
    starts = jnp.asarray([s["reset"] for s in steps])

    def episodes(agent, obs, acts, starts):
        def step(prior, x):
            o, a, start = x
            prior = jtu.tree_map(lambda d, p: jnp.where(start, d, p), agent.D, prior)
            qs = agent.infer_states([o[i][None] for i in range(nm)], prior)
            q_pi, _ = agent.infer_policies(qs)
            action = agent.sample_action(q_pi)
            pred = agent.update_empirical_prior(a[None], qs)
            return pred, (action[0], q_pi[0])

        return lax.scan(step, agent.D, (obs, acts, starts))

    f = jax.jit(episodes)
    t0 = time.perf_counter()
    _, (chosen, q_pi) = jax.block_until_ready(f(agent, obs, acts, starts))
    compile_s = time.perf_counter() - t0
    per_tick = []
    for _ in range(args.reps):
        t0 = time.perf_counter()
        jax.block_until_ready(f(agent, obs, acts, starts))
        per_tick.append((time.perf_counter() - t0) / len(steps) * 1e6)
    print(json.dumps({"tick_us_median": float(np.median(per_tick)), "jit_compile_s": compile_s,
                      "actions": np.asarray(chosen).tolist(), "q_pi": np.asarray(q_pi, dtype=float).tolist(),
                      "policies": np.asarray(agent.policies.policy_arr).tolist(), "jax_version": jax.__version__}))


def same_decisions(ours, theirs):
    """(equal, tied, different) ticks: a tie is our action's best policy within 1e-9 of pymdp's best q_pi."""
    eq = tie = diff = 0
    pols = theirs["policies"]
    for t, (a, b) in enumerate(zip(ours["actions"], theirs["actions"])):
        if a == b:
            eq += 1
            continue
        q = theirs["q_pi"][t]
        best = max(q)
        ours_best = max(qp for p, qp in zip(pols, q) if p[0] == a)
        if best - ours_best <= 1e-9 * max(best, 1.0):
            tie += 1
        else:
            diff += 1
    return eq, tie, diff


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--lens", default="1,2,3,4,5", help="policy lengths (default 1..5)")
    ap.add_argument("--envs", default=",".join(ENVS))
    ap.add_argument("--reps", type=int, default=10, help="timed runs of pymdp's scan (default 10)")
    ap.add_argument("--passes", type=int, default=10, help="timed passes of ours (default 10)")
    ap.add_argument("--bin", default="target/release/examples/aif_ticks")
    ap.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    ap.add_argument("--env")
    ap.add_argument("--policy-len", type=int)
    ap.add_argument("--dtype")
    args = ap.parse_args()
    if args.worker:
        return worker(args)
    from importlib.metadata import version
    print(f"pymdp {version('inferactively-pymdp')}, jax {version('jax')}; µs per planning tick, gate open", file=sys.stderr)
    print("| model | policy_len | policies | ours (µs) | pymdp f32 (µs) | pymdp f64 (µs) | fastest pymdp / ours | same action (f64): equal / tie / differ |")
    print("|---|---|---|---|---|---|---|---|")
    for env in args.envs.split(","):
        for T in [int(x) for x in args.lens.split(",")]:
            ours = json.loads(subprocess.run([args.bin, os.path.join(DATA, f"{env}.json"), str(T), str(args.passes)],
                                             check=True, capture_output=True, text=True).stdout)
            theirs = {}
            for dtype in ["float32", "float64"]:
                out = subprocess.run([sys.executable, __file__, "--worker", "--env", env, "--policy-len", str(T),
                                      "--dtype", dtype, "--reps", str(args.reps)], capture_output=True, text=True)
                theirs[dtype] = json.loads(out.stdout) if out.returncode == 0 else None
                if out.returncode != 0:
                    print(f"{env} T={T} {dtype}: pymdp failed: {out.stderr.strip().splitlines()[-1]}", file=sys.stderr)
            times = [t["tick_us_median"] for t in theirs.values() if t]
            f64 = theirs["float64"]
            dec = "%d / %d / %d" % same_decisions(ours, f64) if f64 else "-"
            fmt = lambda t: f"{t['tick_us_median']:.1f}" if t else "-"
            ratio = f"{min(times) / ours['tick_us_median']:.2f}" if times else "-"
            print(f"| {env} | {T} | {ours['policies']} | {ours['tick_us_median']:.1f} | {fmt(theirs['float32'])} | "
                  f"{fmt(f64)} | {ratio} | {dec} |", flush=True)


if __name__ == "__main__":
    main()

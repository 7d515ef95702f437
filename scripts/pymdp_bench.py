#!/usr/bin/env python3
"""Our in-loop reasoning tick beside pymdp's fastest configurations, in one run (issue 13).

One run does, for each horizon H asked for:

  1. `unforeseen export-model` writes the trained agent's planning model (64 states,
     identity A, 3 actions, terminal states absorbing, C, D, gamma) and `unforeseen
     inspect` our G for the exported observation;
  2. `examples/replay_ticks` records the scaled agent's episodes on the jaywalk family
     (zero-shot, seed 7, 10 per map), replays them and times every reasoning tick alone
     (the `reasoning_tick_replay/H` bench, without criterion); it also writes the
     observations and actions of every recorded tick;
  3. pymdp 1.0.x (JAX) runs its tick -- `infer_states` with the carried empirical prior,
     `infer_policies` over all 3^H policies, `update_empirical_prior` with the recorded
     action -- over that same observation sequence inside one `jax.jit`-compiled
     `lax.scan` (compile time excluded; the fastest way to drive pymdp: no Python per
     tick), in four configurations, each in its own process:
       * flat, float32 and float64: one 64-state factor, `inference_algo="exact"`;
       * factored, float32 and float64: four factors d, v, L, p with one joint
         64-outcome modality (identity A), each factor's B the exact marginal of our
         planning B given the factors it really depends on (checked numerically, so the
         terminal states stay absorbing), `inference_algo="fpi"`. pymdp propagates
         factored beliefs mean-field, so its G differs from the exact one; the script
         prints by how much;
  4. prints one table: ours (median and mean per reasoning tick), each pymdp
     configuration (median per tick over repetitions of the whole scan), and the ratio
     of pymdp's fastest configuration to ours.

Usage (release build first: `cargo build --release --examples`):

    pip install inferactively-pymdp==1.0.4          # brings jax
    OMP_NUM_THREADS=1 taskset -c 1 python3 scripts/pymdp_bench.py --agent agent7.ron --horizons 3,4,5

Without --agent the script trains the default agent (`unforeseen train`, 6000 episodes,
seed 7: the benches' agent) into its work directory first. Both sides run on the CPU the
script is pinned to (`taskset`), XLA with one thread.
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from importlib.metadata import version

import numpy as np

SIZES = [4, 4, 2, 2]  # d, v, L, p (DESIGN.md §4)
CONFIGS = [("flat", "float32"), ("flat", "float64"), ("factored", "float32"), ("factored", "float64")]


def run(cmd, **kw):
    return subprocess.run(cmd, check=True, text=True, capture_output=True, **kw).stdout


# ---------------------------------------------------------------- worker (one pymdp configuration)


def factored_model(m):
    """Per-factor marginals of the joint planning B, each given only the factors it depends on."""
    bj = np.stack([np.asarray(b, dtype=float) for b in m["B"]], axis=0)  # [u, s', s]
    nu = bj.shape[0]
    b6 = bj.reshape(nu, *SIZES, *SIZES)  # [u, d', v', L', p', d, v, L, p]
    nf = len(SIZES)
    B, deps = [], []
    for f in range(nf):
        bf = b6.sum(axis=tuple(1 + g for g in range(nf) if g != f))  # [u, f', d, v, L, p]
        keep = [g for g in range(nf) if g == f or np.max(np.abs(bf - np.take(bf, [0], axis=2 + g))) > 1e-12]
        red = bf
        for g in reversed(range(nf)):
            if g not in keep:
                red = np.take(red, 0, axis=2 + g)
        B.append(np.moveaxis(red, 0, -1))  # [f', deps..., u]
        deps.append(keep)
    d6 = np.asarray(m["D"], dtype=float).reshape(SIZES)
    D = [d6.sum(axis=tuple(g for g in range(nf) if g != f)) for f in range(nf)]
    A = np.eye(int(np.prod(SIZES))).reshape(-1, *SIZES)
    return A, B, deps, D


def worker(args):
    import jax

    if args.dtype == "float64":
        jax.config.update("jax_enable_x64", True)
    import jax.numpy as jnp
    import jax.tree_util as jtu
    from jax import lax
    from pymdp.agent import Agent

    dt = jnp.float64 if args.dtype == "float64" else jnp.float32
    m = json.load(open(args.model))
    seq = json.load(open(args.sequence))
    H, gamma = int(m["policy_len"]), float(m["gamma"])
    C = jnp.asarray(np.asarray(m["C"], dtype=float), dtype=dt)
    if args.kind == "flat":
        A = jnp.asarray(np.asarray(m["A"], dtype=float), dtype=dt)
        B = jnp.asarray(np.stack([np.asarray(b, dtype=float) for b in m["B"]], axis=2), dtype=dt)  # [s', s, u]
        D = jnp.asarray(np.asarray(m["D"], dtype=float), dtype=dt)
        agent = Agent(A=[A[None]], B=[B[None]], C=[C[None]], D=[D[None]], policy_len=H, gamma=gamma,
                      inference_algo="exact", batch_size=1)
        n_factors, deps = 1, None
    else:
        A, Bs, deps, Ds = factored_model(m)
        n_factors = len(Bs)
        agent = Agent(A=[jnp.asarray(A, dtype=dt)[None]], B=[jnp.asarray(b, dtype=dt)[None] for b in Bs],
                      C=[C[None]], D=[jnp.asarray(d, dtype=dt)[None] for d in Ds],
                      A_dependencies=[list(range(n_factors))], B_dependencies=deps,
                      B_action_dependencies=[[0]] * n_factors, num_controls=[len(m["B"])],
                      policy_len=H, gamma=gamma, inference_algo="fpi", num_iter=args.num_iter, batch_size=1)

    def tick(agent, prior, o):
        qs = agent.infer_states([o[None]], prior)
        q_pi, neg_efe = agent.infer_policies(qs)
        return qs, q_pi, neg_efe

    def episodes(agent, obs, acts, starts):
        def step(prior, x):
            o, a, start = x
            prior = jtu.tree_map(lambda d, p: jnp.where(start, d, p), agent.D, prior)
            qs, q_pi, neg_efe = tick(agent, prior, o)
            pred = agent.update_empirical_prior(jnp.broadcast_to(a, (1, n_factors)), qs)
            return pred, q_pi[0]

        return lax.scan(step, agent.D, (obs, acts, starts))

    obs = jnp.asarray(seq["obs"])
    acts = jnp.asarray(seq["actions"])
    starts = jnp.asarray(seq["episode_start"])
    f = jax.jit(episodes)
    t0 = time.perf_counter()
    jax.block_until_ready(f(agent, obs, acts, starts))
    compile_s = time.perf_counter() - t0
    per_tick = []
    for _ in range(args.reps):
        t0 = time.perf_counter()
        jax.block_until_ready(f(agent, obs, acts, starts))
        per_tick.append((time.perf_counter() - t0) / len(seq["obs"]) * 1e6)
    # G of the exported observation from the prior D (what `unforeseen inspect` computes).
    _, _, neg_efe = jax.jit(tick)(agent, agent.D, jnp.asarray(int(m["obs"][-1])))
    per_tick = np.asarray(per_tick)
    print(json.dumps({
        "kind": args.kind, "dtype": args.dtype, "horizon": H, "policies": int(agent.policies.policy_arr.shape[0]),
        "B_dependencies": deps, "ticks": len(seq["obs"]), "reps": args.reps, "jit_compile_s": compile_s,
        "tick_us_median": float(np.median(per_tick)), "tick_us_p10": float(np.percentile(per_tick, 10)),
        "tick_us_p90": float(np.percentile(per_tick, 90)), "G": [-float(x) for x in np.asarray(neg_efe[0])],
        "jax_version": jax.__version__,
    }))


# ---------------------------------------------------------------- orchestration


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--agent", help="trained agent file (default: train the default agent first)")
    ap.add_argument("--bin", default="target/release", help="directory of `unforeseen` and `examples/replay_ticks`")
    ap.add_argument("--horizons", default="3", help="comma-separated horizons (default 3)")
    ap.add_argument("--passes", type=int, default=20, help="replays of our recording (default 20)")
    ap.add_argument("--reps", type=int, default=20, help="timed runs of pymdp's scan (default 20)")
    ap.add_argument("--num-iter", type=int, default=1, help="pymdp fpi iterations, factored (default 1, its fastest)")
    ap.add_argument("--workdir", help="where the intermediate files go (default: a temporary directory)")
    ap.add_argument("--out", help="write all figures as JSON here")
    ap.add_argument("--worker", nargs=4, metavar=("KIND", "DTYPE", "MODEL", "SEQUENCE"), help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.worker:
        args.kind, args.dtype, args.model, args.sequence = args.worker
        return worker(args)

    work = args.workdir or tempfile.mkdtemp(prefix="pymdp_bench_")
    os.makedirs(work, exist_ok=True)
    unforeseen = os.path.join(args.bin, "unforeseen")
    replay = os.path.join(args.bin, "examples", "replay_ticks")
    agent = args.agent
    if agent is None:
        agent = os.path.join(work, "agent.ron")
        print(f"training the default agent into {agent} ...", file=sys.stderr)
        run([unforeseen, "train", "--out", agent, "--quiet"])
    results = {"pymdp_version": version("inferactively-pymdp"), "agent": agent, "horizons": []}
    for h in [int(x) for x in args.horizons.split(",")]:
        model = os.path.join(work, f"model_h{h}.json")
        seq = os.path.join(work, f"sequence_h{h}.json")
        ours_json = os.path.join(work, f"ours_h{h}.json")
        run([unforeseen, "export-model", "--agent", agent, "--set", f"horizon={h}", "--out", model])
        inspect = json.loads(run([unforeseen, "inspect", "--model", model]))
        print(f"H = {h}: replaying our recording ({args.passes} passes) ...", file=sys.stderr)
        run([replay, "--agent", agent, "--horizon", str(h), "--passes", str(args.passes),
             "--json", ours_json, "--write-sequence", seq])
        ours = json.load(open(ours_json))
        rows = []
        for kind, dtype in CONFIGS:
            print(f"H = {h}: pymdp {kind} {dtype} ...", file=sys.stderr)
            out = run([sys.executable, os.path.abspath(__file__), "--reps", str(args.reps), "--num-iter",
                       str(args.num_iter), "--worker", kind, dtype, model, seq])
            r = json.loads(out.strip().splitlines()[-1])
            r["max_abs_G_difference_vs_ours_exact"] = float(np.max(np.abs(np.asarray(r.pop("G")) - np.asarray(inspect["G"]))))
            rows.append(r)
        fastest = min(rows, key=lambda r: r["tick_us_median"])
        entry = {
            "horizon": h,
            "ours": ours,
            "pymdp": rows,
            "pymdp_fastest": f"{fastest['kind']} {fastest['dtype']}",
            "ratio_pymdp_fastest_over_ours_mean": fastest["tick_us_median"] / ours["reasoning"]["mean_us"],
            "ratio_pymdp_fastest_over_ours_median": fastest["tick_us_median"] / ours["reasoning"]["median_us"],
        }
        results["horizons"].append(entry)
        o = ours["reasoning"]
        print(f"\nH = {h}: {ours['reasoning_ticks']} reasoning ticks of {ours['episodes']} recorded episodes "
              f"({ours['ticks']} ticks); pymdp runs its tick on all {ours['ticks']}")
        print(f"  {'who':<40} {'median us':>10} {'p10-p90 us':>17} {'mean us':>9}  G vs ours exact")
        print(f"  {'ours, per reasoning tick':<40} {o['median_us']:>10.2f} {o['p10_us']:>7.2f}-{o['p90_us']:<9.2f} {o['mean_us']:>9.2f}  (exact)")
        for r in rows:
            name = f"pymdp {r['kind']} {r['dtype']} (jit lax.scan)"
            print(f"  {name:<40} {r['tick_us_median']:>10.2f} {r['tick_us_p10']:>7.2f}-{r['tick_us_p90']:<9.2f} {'':>9}  "
                  f"max |dG| = {r['max_abs_G_difference_vs_ours_exact']:.2e}")
        print(f"  pymdp's fastest ({entry['pymdp_fastest']}) / ours: {entry['ratio_pymdp_fastest_over_ours_mean']:.1f}x "
              f"on our mean, {entry['ratio_pymdp_fastest_over_ours_median']:.1f}x on our median")
    if args.out:
        with open(args.out, "w") as f:
            json.dump(results, f, indent=1)


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""Times pymdp on the work of one reasoning tick of the scaled agent (state inference +
expected free energy of every policy of length H), on the agent's own learned model, for
comparison with `cargo bench --bench agent_ticks -- reasoning_tick/3`. See BENCHMARKS.md.

Usage:
    pip install inferactively-pymdp==1.0.4          # brings jax
    cargo run --release -- export-model --out out/model.json
    cargo run --release -- inspect --model out/model.json > out/inspect.json
    OMP_NUM_THREADS=1 taskset -c 1 python3 scripts/pymdp_bench.py out/model.json \
        --inspect out/inspect.json

MODEL.json is the `unforeseen inspect` layout {"A","B","C","D","obs","actions",
"policy_len","gamma"} (A[o][s], B[u][s'][s]); `export-model` writes the trained agent's
planning model (64 states, identity A, 3 actions, terminal states absorbing) with the
jaywalk observation, H = 3 and gamma = 0.5. Without MODEL.json a random 64-state model
(identity A, Dirichlet(1) columns of B, seed 20240611) is used instead.

Backends:
  * jax (default): pymdp 1.0's JAX `Agent`, float64 (`jax_enable_x64`), one function
    `infer_states` + `infer_policies` compiled with `jax.jit` (compile time excluded;
    every timed call ends with `block_until_ready`). Inference algorithm "exact".
  * legacy: pymdp's numpy functions (`pymdp.legacy`): `update_posterior_states` with
    prior D, then `update_posterior_policies` over all policies.
Both evaluate utility + state information gain, i.e. minus our G = risk + ambiguity.

With --inspect REPORT.json (the output of `unforeseen inspect` on the same model) the
script also prints the largest |G_pymdp - G_ours| over all policies, so that the two
timings are known to compute the same numbers.
"""
import argparse
import json
import time
from importlib.metadata import version

import numpy as np

SEED = 20240611


def random_model(ns=64, nu=3):
    rng = np.random.default_rng(SEED)
    A = np.eye(ns)
    B = [rng.dirichlet(np.ones(ns), size=ns).T for _ in range(nu)]  # B[u][s', s]
    C = rng.normal(size=ns) * 2.0
    D = rng.dirichlet(np.ones(ns))
    return {"A": A, "B": B, "C": C, "D": D, "obs": [0], "policy_len": 3, "gamma": 0.5}


def load_model(path):
    with open(path) as f:
        m = json.load(f)
    for key in ("A", "B", "C", "D", "obs", "policy_len", "gamma"):
        if key not in m:
            raise SystemExit(f"{path}: missing key {key!r} (expected the `unforeseen inspect` layout)")
    return m


def bench_jax(m, reps):
    import jax

    jax.config.update("jax_enable_x64", True)
    import jax.numpy as jnp
    from pymdp.agent import Agent

    A = jnp.asarray(np.asarray(m["A"], dtype=float))
    B = jnp.asarray(np.stack([np.asarray(b, dtype=float) for b in m["B"]], axis=2))  # [s', s, u]
    C = jnp.asarray(np.asarray(m["C"], dtype=float))
    D = jnp.asarray(np.asarray(m["D"], dtype=float))
    agent = Agent(
        A=[A[None]],
        B=[B[None]],
        C=[C[None]],
        D=[D[None]],
        policy_len=int(m["policy_len"]),
        gamma=float(m["gamma"]),
        inference_algo="exact",
        batch_size=1,
    )

    @jax.jit
    def tick(agent, obs, prior):
        qs = agent.infer_states([obs], prior)
        q_pi, neg_efe = agent.infer_policies(qs)
        return qs, q_pi, neg_efe

    obs = jnp.array([int(m["obs"][-1])])
    t0 = time.perf_counter()
    out = jax.block_until_ready(tick(agent, obs, agent.D))
    compile_s = time.perf_counter() - t0
    times = []
    for _ in range(reps):
        t0 = time.perf_counter()
        jax.block_until_ready(tick(agent, obs, agent.D))
        times.append(time.perf_counter() - t0)
    g = -np.asarray(out[2][0])
    extra = {"jax_version": jax.__version__, "jit_compile_s": compile_s, "dtype": "float64"}
    return np.asarray(times) * 1e6, g, agent.policies.policy_arr.shape[0], extra


def bench_legacy(m, reps):
    from pymdp.legacy import control, inference, utils

    A = np.asarray(m["A"], dtype=float)
    B = np.stack([np.asarray(b, dtype=float) for b in m["B"]], axis=2)
    ns, nu = B.shape[0], B.shape[2]
    A_obj = utils.obj_array(1)
    A_obj[0] = A
    B_obj = utils.obj_array(1)
    B_obj[0] = B
    C_obj = utils.obj_array(1)
    C_obj[0] = np.asarray(m["C"], dtype=float)
    D = np.asarray(m["D"], dtype=float)
    policies = control.construct_policies([ns], [nu], policy_len=int(m["policy_len"]))
    obs = int(m["obs"][-1])

    def tick():
        qs = inference.update_posterior_states(A_obj, [obs], prior=utils.to_obj_array(D))
        return control.update_posterior_policies(qs, A_obj, B_obj, C_obj, policies, gamma=float(m["gamma"]))

    out = tick()
    times = []
    for _ in range(reps):
        t0 = time.perf_counter()
        tick()
        times.append(time.perf_counter() - t0)
    g = -np.asarray(out[1])
    return np.asarray(times) * 1e6, g, len(policies), {"numpy_version": np.__version__}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("model", nargs="?", help="model JSON in the `unforeseen inspect` layout")
    ap.add_argument("--backend", choices=["jax", "legacy"], default="jax")
    ap.add_argument("--reps", type=int, default=2000)
    ap.add_argument("--inspect", metavar="REPORT.json", help="`unforeseen inspect` output to compare G with")
    args = ap.parse_args()
    m = load_model(args.model) if args.model else random_model()
    source = args.model or f"random 64-state model (seed {SEED})"
    bench = bench_jax if args.backend == "jax" else bench_legacy
    t, g, n_policies, extra = bench(m, args.reps)
    out = {
        "source": source,
        "backend": args.backend,
        "pymdp_version": version("inferactively-pymdp"),
        **extra,
        "states": len(m["D"]),
        "actions": len(m["B"]),
        "horizon": int(m["policy_len"]),
        "policies": n_policies,
        "reps": args.reps,
        "tick_us_median": float(np.median(t)),
        "tick_us_p10": float(np.percentile(t, 10)),
        "tick_us_p90": float(np.percentile(t, 90)),
    }
    if args.inspect:
        with open(args.inspect) as f:
            ours = np.asarray(json.load(f)["G"], dtype=float)
        out["max_abs_G_difference_vs_ours"] = float(np.max(np.abs(ours - g)))
    print(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()

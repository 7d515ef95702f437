#!/usr/bin/env python3
"""Times pymdp (numpy, `pymdp.legacy`) on the work of one reasoning tick of the scaled
agent: state inference + evaluation of every policy of length H, for comparison with
`cargo bench --bench agent_ticks` (`reasoning_tick/3`). See BENCHMARKS.md.

Usage:  pip install inferactively-pymdp==1.0.4
        python3 scripts/pymdp_bench.py [MODEL.json] [--reps N] [--horizon H]

Without MODEL.json it builds an equivalent random single-factor model: 64 states,
identity A (64 observations), 3 actions with random column-stochastic B[u], random C and
D (seed 20240611). With MODEL.json it loads the `unforeseen inspect` layout
{"A","B","C","D","obs","actions","policy_len","gamma"} (A[o][s], B[u][s'][s]) and uses
its policy_len and gamma unless --horizon is given.

Timed per repetition:
  * infer:  prior = B[u] q_prev, `inference.update_posterior_states(A, [o], prior)`
  * policy: `control.update_posterior_policies(qs, A, B, C, policies, gamma)` over all
            n_actions^H policies (27 for H = 3), which computes risk + ambiguity
            (utility + state info gain) along every policy.
"""
import argparse
import json
import time
from importlib.metadata import version

import numpy as np
from pymdp.legacy import control, inference, utils

SEED = 20240611


def random_model(rng, ns=64, nu=3):
    A = np.eye(ns)
    B = np.stack([rng.dirichlet(np.ones(ns), size=ns).T for _ in range(nu)], axis=2)  # B[s', s, u]
    C = rng.normal(size=ns) * 2.0
    D = rng.dirichlet(np.ones(ns))
    return A, B, C, D


def load_model(path):
    m = json.load(open(path))
    A = np.asarray(m["A"], dtype=float)
    B = np.stack([np.asarray(b, dtype=float) for b in m["B"]], axis=2)
    C = np.asarray(m["C"], dtype=float)
    D = np.asarray(m["D"], dtype=float)
    return A, B, C, D, int(m.get("policy_len", 3)), float(m.get("gamma", 0.5))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("model", nargs="?")
    ap.add_argument("--reps", type=int, default=2000)
    ap.add_argument("--horizon", type=int)
    ap.add_argument("--gamma", type=float, default=0.5)
    args = ap.parse_args()
    rng = np.random.default_rng(SEED)
    if args.model:
        A, B, C, D, H, gamma = load_model(args.model)
        source = args.model
    else:
        A, B, C, D = random_model(rng)
        H, gamma, source = 3, args.gamma, "random 64-state model (identity A, 3 actions)"
    if args.horizon:
        H = args.horizon
    ns, nu = B.shape[0], B.shape[2]
    no = A.shape[0]
    A_obj = utils.obj_array(1); A_obj[0] = A
    B_obj = utils.obj_array(1); B_obj[0] = B
    C_obj = utils.obj_array(1); C_obj[0] = C
    policies = control.construct_policies([ns], [nu], policy_len=H)
    q_prev = D.copy()
    obs = [int(rng.integers(no)) for _ in range(args.reps)]
    acts = [int(rng.integers(nu)) for _ in range(args.reps)]

    def infer(k):
        prior = B[:, :, acts[k]].dot(q_prev)
        return inference.update_posterior_states(A_obj, [obs[k]], prior=utils.to_obj_array(prior))

    # warm-up
    for k in range(min(50, args.reps)):
        qs = infer(k)
        control.update_posterior_policies(qs, A_obj, B_obj, C_obj, policies, gamma=gamma)
    t_inf = []
    t_pol = []
    for k in range(args.reps):
        t0 = time.perf_counter()
        qs = infer(k)
        t1 = time.perf_counter()
        control.update_posterior_policies(qs, A_obj, B_obj, C_obj, policies, gamma=gamma)
        t2 = time.perf_counter()
        t_inf.append(t1 - t0)
        t_pol.append(t2 - t1)
    t_inf = np.asarray(t_inf) * 1e6
    t_pol = np.asarray(t_pol) * 1e6
    tot = t_inf + t_pol
    out = {
        "source": source,
        "pymdp_version": version("inferactively-pymdp"),
        "numpy_version": np.__version__,
        "states": ns,
        "observations": no,
        "actions": nu,
        "horizon": H,
        "policies": len(policies),
        "reps": args.reps,
        "infer_us_median": float(np.median(t_inf)),
        "policy_us_median": float(np.median(t_pol)),
        "tick_us_median": float(np.median(tot)),
        "tick_us_p10": float(np.percentile(tot, 10)),
        "tick_us_p90": float(np.percentile(tot, 90)),
    }
    print(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""Reference values for `unforeseen inspect` produced by pymdp (inferactively-pymdp).

Usage:  pip install inferactively-pymdp==1.0.4
        python3 scripts/pymdp_reference.py > agent/tests/data/pymdp_reference.json

Uses pymdp's numpy implementation (`pymdp.legacy`, shipped with 1.0.4), seed 20240611.
Conventions converted here (and checked by agent/tests/pymdp_crossval.rs):
  * pymdp's `update_posterior_policies` returns `neg_efe` ("G" in its docs), i.e.
    minus the expected free energy: utility + state info gain. The paper's (and our) G
    is risk + ambiguity = -(neg_efe). We store G = -neg_efe.
  * pymdp softmaxes C before taking logs (calc_expected_utility: ln softmax(C)); ours
    applies log_softmax to C too, so both use the same normalised preferences.
  * pymdp's q_pi = softmax(gamma * neg_efe + ln E) with E uniform = softmax(-gamma G).
  * pymdp logs add EPS 1e-16 (log(x + 1e-16)); ours floors (log(max(x, 1e-16))). All
    probabilities here are far from 0, so the difference is below 1e-12. But pymdp's
    state info gain (spm_MDP_G) adds exp(-16) ~ 1.1e-7 inside its logs, so its G is off
    by ~1e-6 from the exact value; the Rust test compares G, q_pi, psi at 1e-5
    (qs, F and surprise at 1e-8).
  * qs: exact filtering with pymdp's `update_posterior_states` (vanilla FPI, exact for
    one factor and one modality) using prior = B[u] q_{t-1} (D at t = 1).
  * F: pymdp's `calc_free_energy(qs, prior, 1, likelihood)` at the last step, which for
    the exact posterior equals -ln p(o_t | o_1..t-1) = the surprise.
"""
import json
import sys

import numpy as np
from importlib.metadata import version
from pymdp.legacy import control, inference, utils, maths

SEED = 20240611


def case(rng, ns, no, nu, t, H, gamma):
    A = rng.dirichlet(np.ones(no), size=ns).T          # A[o, s]
    B = np.stack([rng.dirichlet(np.ones(ns), size=ns).T for _ in range(nu)], axis=2)  # B[s', s, u]
    C = rng.normal(size=no) * 2.0
    D = rng.dirichlet(np.ones(ns))
    obs = [int(rng.integers(no)) for _ in range(t)]
    actions = [int(rng.integers(nu)) for _ in range(t - 1)]

    A_obj = utils.obj_array(1); A_obj[0] = A
    B_obj = utils.obj_array(1); B_obj[0] = B
    C_obj = utils.obj_array(1); C_obj[0] = C
    qs = None
    for k, o in enumerate(obs):
        prior = D if k == 0 else B[:, :, actions[k - 1]].dot(qs[0])
        qs = inference.update_posterior_states(A_obj, [o], prior=utils.to_obj_array(prior))
        last_prior = prior
    # free energy at the last step (pymdp: likelihood is ln p(o|s) for the observed o)
    likelihood = maths.spm_log_single(maths.get_joint_likelihood(A_obj, utils.to_obj_array(np.eye(no)[obs[-1]]), [ns]))
    # calc_free_energy expects the prior in log space (xH_qp = -qs . prior)
    F = maths.calc_free_energy(qs, utils.to_obj_array(np.log(last_prior)), 1, likelihood)
    surprise = -np.log(A[obs[-1], :].dot(last_prior))
    policies = control.construct_policies([ns], [nu], policy_len=H)
    q_pi, neg_efe = control.update_posterior_policies(qs, A_obj, B_obj, C_obj, policies, gamma=gamma)
    G = -np.asarray(neg_efe).ravel()
    pol_list = [[int(p[k, 0]) for k in range(H)] for p in policies]
    psi = [float(sum(q for q, p in zip(np.asarray(q_pi).ravel(), pol_list) if p[0] == u)) for u in range(nu)]
    model = {
        "A": A.tolist(),
        "B": [B[:, :, u].tolist() for u in range(nu)],
        "C": C.tolist(),
        "D": D.tolist(),
        "obs": obs,
        "actions": actions,
        "policy_len": H,
        "gamma": gamma,
    }
    expected = {
        "qs": qs[0].tolist(),
        "F": float(np.asarray(F).ravel()[0]),
        "surprise": float(surprise),
        "policies": pol_list,
        "G": G.tolist(),
        "q_pi": np.asarray(q_pi).ravel().tolist(),
        "psi": psi,
    }
    return {"model": model, "expected": expected}


def main():
    rng = np.random.default_rng(SEED)
    cases = [
        case(rng, ns=3, no=3, nu=2, t=3, H=2, gamma=2.0),
        case(rng, ns=4, no=3, nu=3, t=4, H=2, gamma=0.5),
        case(rng, ns=2, no=2, nu=2, t=1, H=3, gamma=16.0),
    ]
    out = {
        "generator": "scripts/pymdp_reference.py",
        "pymdp_version": version("inferactively-pymdp"),
        "numpy_version": np.__version__,
        "seed": SEED,
        "G_convention": "G = -neg_efe (pymdp returns neg_efe); lower is better",
        "cases": cases,
    }
    json.dump(out, sys.stdout, indent=1)
    sys.stdout.write("\n")


if __name__ == "__main__":
    main()

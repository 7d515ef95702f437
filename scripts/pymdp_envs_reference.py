#!/usr/bin/env python3
"""Reference runs of pymdp 1.0.4 (JAX) on its own environments, for agent/tests/it/aif_pymdp.rs.

Usage:  pip install inferactively-pymdp==1.0.4
        python3 scripts/pymdp_envs_reference.py agent/tests/data/pymdp

Writes one JSON file per environment (T-maze, generalized T-maze, grid world, cue chaining).
The generative model is the environment's own A, B, D (A_dependencies, B_dependencies),
built by pymdp's code with its default arguments; C is the preference named in MODELS below
(pymdp's environments carry none). The agent is pymdp's `Agent` with its defaults
(fpi, num_iter=16, gamma=1, deterministic full action selection) and the policy length
named below. JAX runs in float64.

Each file holds
  * `rollout`: 50 steps in the environment (seed below), reset every 10 steps (the prior
    is then D again). Per step: the observation, then pymdp's qs, its VFE
    (`infer_states(return_info=True)`), G = -neg_efe per policy (lower is better; pymdp
    returns neg_efe), q_pi, the action it chose (sampling_mode "full") and the action of
    sampling_mode "marginal". The empirical prior of step t+1 is pymdp's
    `update_empirical_prior(action_t, qs_t)`.
  * `param_info_gain`: the same for 20 steps with `use_param_info_gain=True` and the
    Dirichlet counts pA0, pB0 of `learning`.
  * `learning`: 10 episodes of 10 steps with pA and pB (Dirichlet, lr 1) learned by
    `infer_parameters` at each episode's end, from the episode's filtered beliefs; per
    episode the observations and actions, and at the end pA, pB.
"""
import json
import os
import sys
from importlib.metadata import version

import jax
import jax.numpy as jnp
import numpy as np

jax.config.update("jax_enable_x64", True)

import equinox as eqx  # noqa: E402
from pymdp.agent import Agent  # noqa: E402
from pymdp import control  # noqa: E402
from pymdp.envs import cue_chaining, generalized_tmaze, grid_world, tmaze  # noqa: E402

SEED = 20261203
ROLLOUT_STEPS = 50
EPISODES = 10
EPISODE_STEPS = 10


def reward_c(num_obs_list, modality, values):
    """C: zeros, except `values` on the reward modality (no outcome, reward, punishment)."""
    return [jnp.array(values, dtype=jnp.float64) if m == modality else jnp.zeros(n) for m, n in enumerate(num_obs_list)]


def build(name):
    if name == "tmaze":
        env = tmaze.TMaze()
        c = reward_c([a.shape[0] for a in env.A], 1, [0.0, 2.0, -4.0])
        return env, c, 3
    if name == "generalized_tmaze":
        info = generalized_tmaze.parse_maze(generalized_tmaze.get_maze_matrix(small=True), jax.random.PRNGKey(0))
        env = generalized_tmaze.GeneralizedTMazeEnv(info)
        n = [a.shape[0] for a in env.A]
        c = [jnp.zeros(k) for k in n]
        # modalities 1..num_cues are the reward modalities (no outcome, reward, punishment)
        for m in range(1, 1 + info["num_cues"]):
            c[m] = jnp.array([0.0, 2.0, -4.0])
        return env, c, 2
    if name == "grid_world":
        env = grid_world.GridWorld()
        n = env.A[0].shape[0]
        goal = n - 1
        c = [jnp.zeros(n).at[goal].set(3.0)]
        return env, c, 3
    if name == "cue_chaining":
        env = cue_chaining.CueChainingEnv()
        c = reward_c([a.shape[0] for a in env.A], 3, [0.0, 3.0, -3.0])
        return env, c, 4
    raise ValueError(name)


def as_list(xs):
    return [np.asarray(x).tolist() for x in xs]


def f64(x):
    return jnp.asarray(x, dtype=jnp.float64)


def make_agent(env, c, policy_len, pA=None, pB=None, learn=False, sampling_mode="full", param_info_gain=False):
    A = [f64(a) for a in env.A]
    B = [f64(b) for b in env.B]
    if pA is not None:
        A = [p / p.sum(axis=0, keepdims=True) for p in pA]
    if pB is not None:
        B = [p / p.sum(axis=0, keepdims=True) for p in pB]
    return Agent(
        A, B, C=[f64(x) for x in c], D=[f64(d) for d in env.D], pA=pA, pB=pB,
        A_dependencies=env.A_dependencies, B_dependencies=env.B_dependencies,
        policy_len=policy_len, learn_A=learn, learn_B=learn, sampling_mode=sampling_mode,
        use_param_info_gain=param_info_gain,
    )


@eqx.filter_jit
def tick(agent, obs, prior):
    qs, info = agent.infer_states(obs, prior, return_info=True)
    q_pi, neg_efe = agent.infer_policies(qs)
    action = agent.sample_action(q_pi)
    return qs, q_pi, neg_efe, action, info["vfe"]


def rounded(x):
    """Nested lists of floats with 12 significant digits (1e-11 relative, far below the
    tests' 1e-6), to keep the files small."""
    if isinstance(x, list):
        return [rounded(v) for v in x]
    if isinstance(x, float):
        return float(f"{x:.12g}")
    return x


@eqx.filter_jit
def marginal_action(policies, num_controls, q_pi):
    return control.sample_action(policies, num_controls, q_pi, action_selection="deterministic")


@eqx.filter_jit
def next_prior(agent, action, qs):
    return agent.update_empirical_prior(action, qs)


def rollout(env, agent, key, steps_total=ROLLOUT_STEPS):
    steps = []
    for t in range(steps_total):
        if t % EPISODE_STEPS == 0:
            key, k = jax.random.split(key)
            obs, state = env.reset(k)
            prior = agent.D
        o = [jnp.asarray(x, dtype=jnp.int32) for x in obs]  # each (1,)
        qs, q_pi, neg_efe, action, vfe = tick(agent, o, prior)
        marg = marginal_action(agent.policies.policy_arr, agent.num_controls, q_pi[0])
        steps.append({
            "reset": t % EPISODE_STEPS == 0,
            "obs": [int(x[0]) for x in o],
            "qs": rounded([np.asarray(q[0, -1]).tolist() for q in qs]),
            "vfe": rounded(float(np.asarray(vfe).ravel()[-1])),
            "G": rounded((-np.asarray(neg_efe[0])).tolist()),
            "q_pi": rounded(np.asarray(q_pi[0]).tolist()),
            "action": np.asarray(action[0]).astype(int).tolist(),
            "action_marginal": np.asarray(marg).astype(int).tolist(),
        })
        prior = next_prior(agent, action, qs)
        key, k = jax.random.split(key)
        obs, state = env.step(k, state, action[0])
    return steps


def prior_counts(env):
    """pA0, pB0: the environment's arrays as weak counts, 2 A + 0.5 (so A = E[pA] differs from the truth)."""
    return [f64(a) * 2.0 + 0.5 for a in env.A], [f64(b) * 2.0 + 0.5 for b in env.B]


def learning(env, c, policy_len, key):
    pA, pB = prior_counts(env)
    pA0, pB0 = as_list(pA), as_list(pB)
    agent = make_agent(env, c, policy_len, pA=pA, pB=pB, learn=True)
    episodes = []
    for _ in range(EPISODES):
        key, k = jax.random.split(key)
        obs, state = env.reset(k)
        prior = agent.D
        qs_hist, obs_hist, act_hist = [], [], []
        for _ in range(EPISODE_STEPS):
            o = [jnp.asarray(x, dtype=jnp.int32) for x in obs]
            qs, q_pi, neg_efe, action, _ = tick(agent, o, prior)
            qs_hist.append([q[:, -1] for q in qs])
            obs_hist.append([int(x[0]) for x in o])
            act_hist.append(np.asarray(action[0]).astype(int).tolist())
            prior = next_prior(agent, action, qs)
            key, k = jax.random.split(key)
            obs, state = env.step(k, state, action[0])
        nf = len(agent.B)
        beliefs = [jnp.stack([q[f] for q in qs_hist], axis=1) for f in range(nf)]  # (1, T, Ns_f)
        observations = [jnp.array([[o[m] for o in obs_hist]]) for m in range(len(agent.A))]  # (1, T)
        actions = jnp.array([act_hist])  # (1, T, nf)
        agent = agent.infer_parameters(beliefs, observations, actions, beliefs_B=beliefs)
        episodes.append({"obs": obs_hist, "actions": act_hist})
    return {
        "lr_pA": 1.0,
        "lr_pB": 1.0,
        "pA0": pA0,
        "pB0": pB0,
        "episodes": episodes,
        "pA": rounded([np.asarray(p[0]).tolist() for p in agent.pA]),
        "pB": rounded([np.asarray(p[0]).tolist() for p in agent.pB]),
    }


def main():
    out_dir = sys.argv[1] if len(sys.argv) > 1 else "agent/tests/data/pymdp"
    os.makedirs(out_dir, exist_ok=True)
    for i, name in enumerate(["tmaze", "generalized_tmaze", "grid_world", "cue_chaining"]):
        env, c, policy_len = build(name)
        agent = make_agent(env, c, policy_len)
        data = {
            "generator": "scripts/pymdp_envs_reference.py",
            "pymdp_version": version("inferactively-pymdp"),
            "jax_version": jax.__version__,
            "dtype": "float64",
            "seed": SEED + i,
            "env": name,
            "G_convention": "G = -neg_efe (pymdp returns neg_efe); lower is better",
            "model": {
                "A": as_list(agent.A[m][0] for m in range(len(env.A))),
                "B": as_list(agent.B[f][0] for f in range(len(env.B))),
                "C": as_list(agent.C[m][0] for m in range(len(env.A))),
                "D": as_list(agent.D[f][0] for f in range(len(env.B))),
                "A_dependencies": [list(map(int, d)) for d in env.A_dependencies],
                "B_dependencies": [list(map(int, d)) for d in env.B_dependencies],
                "policy_len": policy_len,
                "gamma": 1.0,
                "num_iter": 16,
            },
            "policies": np.asarray(agent.policies.policy_arr).astype(int).tolist(),
            "rollout": rollout(env, agent, jax.random.PRNGKey(SEED + i)),
            "learning": learning(env, c, policy_len, jax.random.PRNGKey(SEED + 100 + i)),
            "param_info_gain": rollout(
                env,
                make_agent(env, c, policy_len, *prior_counts(env), param_info_gain=True),
                jax.random.PRNGKey(SEED + 200 + i),
                steps_total=20,
            ),
        }
        path = os.path.join(out_dir, f"{name}.json")
        with open(path, "w") as f:
            json.dump(data, f, separators=(",", ":"))
            f.write("\n")
        print(path, os.path.getsize(path), file=sys.stderr)


if __name__ == "__main__":
    main()

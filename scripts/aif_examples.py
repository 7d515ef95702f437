#!/usr/bin/env python3
"""Example files for `unforeseen run-model`, derived from pymdp's T-maze as stored in
agent/tests/data/pymdp/tmaze.json (no JAX needed).

Usage:  python3 scripts/aif_examples.py examples/models

Writes
  * tmaze_model.json: the agent's model (pymdp's T-maze A, B, D, the script's C) with pA,
    pB = 10 A + 0.1, 10 B + 0.1 (for --learn) and its settings (policy_len 3);
  * tmaze_env.json: the world the model describes (cue validity 0.95);
  * tmaze_env_cue_lies.json: an unforeseen change of the T-maze's own kind, the cue now
    points to the wrong arm with probability 0.95 (A[2] at the cue location swapped).
"""
import json
import os
import sys

CUE_LOCATION = 3  # pymdp's T-maze: centre 0, left 1, right 2, cue 3, middle 4


def counts(x):
    if isinstance(x, list):
        return [counts(v) for v in x]
    return 10.0 * x + 0.1


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else "examples/models"
    ref = json.load(open("agent/tests/data/pymdp/tmaze.json"))
    m = ref["model"]
    model = {k: m[k] for k in ("A", "B", "C", "D", "A_dependencies", "B_dependencies", "policy_len", "gamma", "num_iter")}
    model["pA"] = counts(m["A"])
    model["pB"] = counts(m["B"])
    # With pA, pB given, the model's A and B are their expected values (as pymdp learns them).
    def normalise(p):
        # p[o][...]: divide by the sum over axis 0
        import itertools
        def shape(x):
            return [len(x)] + shape(x[0]) if isinstance(x, list) else []
        sh = shape(p)
        def get(x, idx):
            for i in idx:
                x = x[i]
            return x
        def put(x, idx, v):
            for i in idx[:-1]:
                x = x[i]
            x[idx[-1]] = v
        q = json.loads(json.dumps(p))
        for col in itertools.product(*[range(n) for n in sh[1:]]):
            z = sum(get(p, (o,) + col) for o in range(sh[0]))
            for o in range(sh[0]):
                put(q, (o,) + col, get(p, (o,) + col) / z)
        return q
    model["A"] = [normalise(p) for p in model["pA"]]
    model["B"] = [normalise(p) for p in model["pB"]]
    env = {k: m[k] for k in ("A", "B", "D", "A_dependencies", "B_dependencies")}
    lies = json.loads(json.dumps(env))
    for cond in range(2):
        right, wrong = lies["A"][2][1 + cond][CUE_LOCATION][cond], lies["A"][2][2 - cond][CUE_LOCATION][cond]
        lies["A"][2][1 + cond][CUE_LOCATION][cond], lies["A"][2][2 - cond][CUE_LOCATION][cond] = wrong, right
    os.makedirs(out, exist_ok=True)
    for name, data in [("tmaze_model", model), ("tmaze_env", env), ("tmaze_env_cue_lies", lies)]:
        with open(os.path.join(out, f"{name}.json"), "w") as f:
            json.dump({"generator": "scripts/aif_examples.py", **data}, f, separators=(",", ":"))
            f.write("\n")


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""The gate on pymdp's T-maze when the cue starts to lie (issue 46): `unforeseen run-model`
with the shipped model (examples/models/tmaze_model.json, pA/pB learned after every
episode) in the world it describes and in the world whose cue points to the wrong arm
(tmaze_env_cue_lies.json), for several ε, over seeds; prints a markdown table of the mean
return per episode (95% interval over seeds, t-based), its worst seed, and the fraction
of ticks planned. ε < 0 plans on every tick (pymdp's loop).

Usage:  cargo build --release
        python3 scripts/aif_tmaze_change.py --seeds 11..20
"""
import argparse
import json
import math
import statistics
import subprocess

T975 = {2: 12.71, 3: 4.30, 4: 3.18, 5: 2.78, 6: 2.57, 7: 2.45, 8: 2.36, 9: 2.31, 10: 2.26, 11: 2.23}


def seeds(spec):
    a, b = spec.split("..")
    return list(range(int(a), int(b) + 1))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--seeds", default="11..20")
    ap.add_argument("--eps", default="-1,0.25,0.5,1,2,1000")
    ap.add_argument("--episodes", type=int, default=30)
    ap.add_argument("--steps", type=int, default=10)
    ap.add_argument("--bin", default="target/release/unforeseen")
    args = ap.parse_args()
    print("| world | ε (bits) | return per episode, mean [95%] | worst seed | ticks planned |")
    print("|---|---|---|---|---|")
    for world in ["tmaze_env", "tmaze_env_cue_lies"]:
        for eps in args.eps.split(","):
            rets, planned = [], []
            for s in seeds(args.seeds):
                out = subprocess.run([args.bin, "run-model", "--model", "examples/models/tmaze_model.json",
                                      "--env", f"examples/models/{world}.json", "--episodes", str(args.episodes),
                                      "--steps", str(args.steps), "--epsilon", eps, "--seed", str(s), "--learn"],
                                     check=True, capture_output=True, text=True).stdout
                r = json.loads(out)
                rets.append(r["mean_return"])
                planned.append(r["planned_fraction"])
            n = len(rets)
            m = statistics.mean(rets)
            h = T975.get(n, 1.96) * statistics.stdev(rets) / math.sqrt(n) if n > 1 else float("nan")
            print(f"| {world} | {eps} | {m:.2f} [{m - h:.2f}, {m + h:.2f}] | {min(rets):.2f} | {statistics.mean(planned):.3f} |")


if __name__ == "__main__":
    main()

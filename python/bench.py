"""Steps per second: the Rust loop alone, a single env driven from Python, the native
vector env at 16/64/256 envs, and (if installed, in a separate venv) highway-env's
``intersection-v0`` at the same decision rates (1 Hz and 10 Hz).

    python python/bench.py                      # unforeseen only
    python python/bench.py --highway            # also highway-env (pip install highway-env in a bench venv)
    python python/bench.py --only highway       # highway-env only (run it from the bench venv)

Every figure is the best of ``--repeats`` runs (like ``timeit``: on a shared machine the
best run is the one least disturbed), the runs of all configurations interleaved so
that each sees the same load; ``vector_cpu_per_wall`` says how many cores a vector run
got, and ``cpu_us_per_env_step`` what a step cost in CPU time, all threads counted (the
least of the runs): the vector env's rate over the single env's is about the cores it
got times the single env's CPU per step over its own. The actions are the same fixed cycle
everywhere (speed up, maintain, slow down, speed up), and episodes restart as they end.
Results are printed as one JSON object (nothing else is printed); ``package`` is the
file of the package measured.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

# Run as a script, Python puts this file's folder first on sys.path: python/, which holds
# the package's source without its compiled extension and would shadow the installed
# package (an editable install adds python/ again, later on the path). The benchmark
# measures the installed package.
if sys.path and Path(sys.path[0] or ".").resolve() == Path(__file__).resolve().parent:
    del sys.path[0]

ACTIONS = [1, 0, 2, 1]


def best_rates(runs: dict, repeats: int) -> dict:
    """Runs every configuration ``repeats`` times, interleaved; the best rate of each."""
    best: dict = {k: 0.0 for k in runs}
    for _ in range(repeats):
        for k, run in runs.items():
            best[k] = max(best[k], run())
    return best


def unforeseen_figures(map_name: str, steps: int, repeats: int, hz: int) -> dict:
    import unforeseen
    from unforeseen import _unforeseen

    overrides = {} if hz == 1 else {"decision_dt": 1.0 / hz, "max_steps": 40 * hz}
    out: dict = {"map": map_name, "decision_hz": hz}

    def rust() -> float:
        n, secs, _ = _unforeseen.rust_loop(map_name, ACTIONS, steps, 0, "discrete", overrides)
        return n / secs

    # CPU µs per env step (all threads), the least of the runs: what a step costs
    # whatever the number of cores the run got.
    cpu_us: dict = {}

    def note_cpu(key: str, c0: float, env_steps: int) -> None:
        cpu_us[key] = min(cpu_us.get(key, float("inf")), (time.process_time() - c0) / env_steps * 1e6)

    def single() -> float:
        env = unforeseen.make_env(map_name, **overrides)
        env.reset(seed=0)
        t0, c0 = time.perf_counter(), time.process_time()
        for t in range(steps):
            _, _, term, trunc, _ = env.step(ACTIONS[t % 4])
            if term or trunc:
                env.reset()
        note_cpu("single", c0, steps)
        return steps / (time.perf_counter() - t0)

    cpu_share: dict = {}

    def vector(n: int):
        def run() -> float:
            env = unforeseen.VectorEnv(map_name, n, **overrides)
            env.reset(seed=0)
            calls = max(steps // n, 20)
            acts = [np.full(n, a, dtype=np.int64) for a in ACTIONS]
            t0, c0 = time.perf_counter(), time.process_time()
            for t in range(calls):
                env.step(acts[t % 4])
            wall = time.perf_counter() - t0
            rate = calls * n / wall
            note_cpu(f"vector_{n}", c0, calls * n)
            if rate >= cpu_share.get(n, (0.0, 0.0))[0]:
                cpu_share[n] = (rate, (time.process_time() - c0) / wall)
            return rate

        return run

    runs = {"rust_loop_steps_per_s": rust, "single_env_python_steps_per_s": single}
    runs.update({f"vector_{n}_steps_per_s": vector(n) for n in (16, 64, 256)})
    out.update(best_rates(runs, repeats))
    r, s = out["rust_loop_steps_per_s"], out["single_env_python_steps_per_s"]
    out["python_overhead_share_of_rust_step_time"] = (1 / s - 1 / r) / (1 / r)
    out["vector_64_over_single"] = out["vector_64_steps_per_s"] / s
    out["vector_cpu_per_wall"] = {n: round(c, 2) for n, (_, c) in sorted(cpu_share.items())}
    out["cpu_us_per_env_step"] = {k: round(v, 2) for k, v in cpu_us.items()}
    return out


def highway_figures(hz: int, steps: int, repeats: int) -> dict:
    import gymnasium as gym
    import highway_env  # noqa: F401  (registers the envs)

    gym.logger.min_level = gym.logger.ERROR  # intersection-v0's deprecation notice

    def run() -> float:
        env = gym.make("intersection-v0", config={"policy_frequency": hz, "duration": 40})
        env.reset(seed=0)
        t0 = time.perf_counter()
        for t in range(steps):
            _, _, term, trunc, _ = env.step(ACTIONS[t % 4] % env.action_space.n)
            if term or trunc:
                env.reset()
        return steps / (time.perf_counter() - t0)

    return {"decision_hz": hz, "steps_per_s": best_rates({"run": run}, repeats)["run"]}


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--map", default="jaywalk")
    p.add_argument("--steps", type=int, default=20000)
    p.add_argument("--repeats", type=int, default=5)
    p.add_argument("--highway", action="store_true", help="also run highway-env")
    p.add_argument("--highway-steps", type=int, default=300)
    p.add_argument("--only", choices=["unforeseen", "highway"])
    a = p.parse_args()
    results: dict = {}
    if a.only != "highway":
        import unforeseen

        results["package"] = unforeseen.__file__  # the package measured
        results["unforeseen"] = [unforeseen_figures(a.map, a.steps, a.repeats, hz) for hz in (1, 10)]
    if a.highway or a.only == "highway":
        results["highway_env"] = [highway_figures(hz, a.highway_steps, a.repeats) for hz in (1, 10)]
    print(json.dumps(results, indent=2))


if __name__ == "__main__":
    main()

"""Units/s of one sweep (maps/, an agent file, 20 episodes, one unit per task) on a Ray
cluster with N CPUs, and the overhead of a task. Inside scripts/ray_local_cluster.sh:
  RAY=.venv/bin/ray scripts/ray_local_cluster.sh NS N 0 -- .venv/bin/python scripts/ray_scaling.py 127.0.0.1:6379 agent.ron /tmp/out.jsonl N"""
import json, sys, time, os
import ray
from unforeseen import _unforeseen, distributed as d
addr, agent, out, n = sys.argv[1], sys.argv[2], sys.argv[3], int(sys.argv[4])
ray.init(address=addr, log_to_driver=False)
assert int(ray.cluster_resources()["CPU"]) == n
t = time.monotonic()
r = d.run_batch(["maps/"], out=out, agent=agent, episodes=20, units_per_task=1, force=True, quiet=True)
wall = time.monotonic() - t
units = len(r["lines"])
# Overhead per task: a task that rebuilds the run and runs no unit, 200 times.
plan = json.loads(_unforeseen.plan_batch(json.dumps({"maps": ["maps/"], "out": out + ".overhead.jsonl", "episodes": 20,
                                                     "agent": agent, "force": True})))
ref = ray.put(plan["agent"].encode())
task = ray.remote(num_cpus=1, **d._task_options(3))(d._units_task)
seed = plan["todo_seeds"][0]
ray.get([task.remote(plan["spec"], [seed], ref, units=[], threads=1) for _ in range(4)])
t = time.monotonic(); ray.get([task.remote(plan["spec"], [seed], ref, units=[], threads=1) for _ in range(200)]); empty = (time.monotonic() - t) / 200
noop = ray.remote(num_cpus=1)(lambda: None)
ray.get([noop.remote() for _ in range(4)])
t = time.monotonic(); ray.get([noop.remote() for _ in range(200)]); bare = (time.monotonic() - t) / 200
size = sum(len(json.dumps(l)) for l in r["lines"]) / units
print(json.dumps({"workers": n, "units": units, "wall_s": round(wall, 2), "units_per_s": round(units / wall, 2),
                  "empty_unit_task_ms": round(empty * 1e3, 2), "noop_task_ms": round(bare * 1e3, 2),
                  "agent_bytes": len(plan["agent"]), "line_bytes": round(size)}))

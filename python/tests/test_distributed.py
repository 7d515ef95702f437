"""unforeseen.distributed on a real local Ray cluster: a head and a second worker node,
started as separate processes inside a network namespace with only loopback up (nothing
leaves the machine; usage statistics off). A sweep whose worker node is killed mid-run
equals the command line's one-machine run of it; an input error fails once, a dead
worker is retried. The cluster's processes and the namespace are removed whatever
happens. Where namespaces cannot be made (not root, no `ip`), the cluster tests skip
(or fail, under UNFORESEEN_REQUIRE_RAY_CLUSTER=1 as in CI)."""

from __future__ import annotations

import importlib.util
import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import types
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from test_agents import required_cli

REPO = Path(__file__).resolve().parents[2]
PORT = 6379
ADDRESS = f"127.0.0.1:{PORT}"
# Every wait has a deadline (seconds).
START_TIMEOUT = 180
RUN_TIMEOUT = 300
# The sweep: two maps, two training seeds, one unit per task.
SWEEP = ["batch", str(REPO / "maps" / "jaywalk.ron"), str(REPO / "maps" / "stop_midway.ron"),
         "--train-seeds", "1..2", "--train-episodes", "200", "--episodes", "6", "--seed", "5"]


def test_a_bad_field_is_named_as_the_field_in_python_and_as_the_flag_on_the_command_line(tmp_path: Path):
    """The request's planning names the field; the Ray driver's command spells it as the
    command line's flag, as `unforeseen batch` does."""
    from unforeseen.distributed import run_batch

    for bad in ["3..1", "1,1", "x"]:
        with pytest.raises(ValueError, match="^train_seeds: "):
            run_batch(["jaywalk"], train_seeds=bad, out=tmp_path / "r.jsonl")
    run = subprocess.run([sys.executable, "-m", "unforeseen.distributed", "batch", "jaywalk", "--train-seeds", "3..1",
                          "--out", str(tmp_path / "r.jsonl"), "--address", "127.0.0.1:9"],
                         capture_output=True, text=True, timeout=60)
    assert run.returncode == 2 and "error: --train-seeds: '3..1': the range runs backwards" in run.stderr, run.stderr
    assert not (tmp_path / "r.jsonl").exists()


def test_bad_input_fails_before_any_task_with_its_reason(tmp_path: Path):
    bad = tmp_path / "bad.ron"
    bad.write_text("Map(name: \"bad\", lanes: 7)\n")
    out = tmp_path / "r.jsonl"
    run = subprocess.run([sys.executable, "-m", "unforeseen.distributed", "batch", str(bad), "--out", str(out),
                          "--address", "127.0.0.1:9"], capture_output=True, text=True, timeout=60)
    assert run.returncode == 2, run.stderr
    assert "bad.ron" in run.stderr and "error:" in run.stderr and "Traceback" not in run.stderr
    assert not out.exists()
    shard = subprocess.run([sys.executable, "-m", "unforeseen.distributed", "batch", "--shard", "1/2"],
                           capture_output=True, text=True, timeout=60)
    assert shard.returncode == 2 and "unforeseen merge" in shard.stderr, shard.stderr


def _unavailable(reason: str) -> None:
    if os.environ.get("UNFORESEEN_REQUIRE_RAY_CLUSTER") == "1":
        pytest.fail(f"the Ray cluster tests must run here: {reason}")
    pytest.skip(reason)


def _env() -> dict[str, str]:
    env = dict(os.environ, RAY_USAGE_STATS_ENABLED="0",
               # A dead node is noticed in about 2 s instead of 15.
               RAY_health_check_period_ms="500", RAY_health_check_failure_threshold="4")
    env.pop("RAY_ADDRESS", None)
    return env


class Namespace:
    """A network namespace with only `lo` up, and the processes started in it."""

    def __init__(self) -> None:
        self.name = f"unf-ray-{os.getpid()}"
        self.ok = False

    def create(self) -> str | None:
        if shutil.which("ip") is None:
            return "no `ip` command (iproute2) to make a network namespace"
        made = subprocess.run(["ip", "netns", "add", self.name], capture_output=True, text=True, timeout=30)
        if made.returncode != 0:
            return f"cannot create a network namespace (needs root): {made.stderr.strip()}"
        self.ok = True
        subprocess.run(["ip", "netns", "exec", self.name, "ip", "link", "set", "lo", "up"], check=True, timeout=30)
        return None

    def run(self, args: list[str], timeout: float, **kw) -> subprocess.CompletedProcess[str]:
        return subprocess.run(["ip", "netns", "exec", self.name, *args], capture_output=True, text=True,
                              timeout=timeout, env=_env(), **kw)

    def pids(self) -> set[int]:
        if not self.ok:
            return set()
        out = subprocess.run(["ip", "netns", "pids", self.name], capture_output=True, text=True, timeout=30)
        return {int(p) for p in out.stdout.split()}

    def interfaces(self) -> str:
        return self.run(["ip", "-o", "link", "show", "up"], timeout=30).stdout

    def destroy(self) -> None:
        if not self.ok:
            return
        # Only the processes inside this namespace (ours), by id; then the namespace.
        for _ in range(3):
            pids = self.pids()
            if not pids:
                break
            for p in pids:
                try:
                    os.kill(p, signal.SIGKILL)
                except ProcessLookupError:
                    pass
            for p in pids:
                _wait_gone(p, 10)
        subprocess.run(["ip", "netns", "del", self.name], capture_output=True, timeout=30)
        self.ok = False


def _wait_gone(pid: int, timeout: float) -> None:
    deadline = time.monotonic() + timeout
    while Path(f"/proc/{pid}").exists() and time.monotonic() < deadline:
        try:
            os.waitpid(pid, os.WNOHANG)
        except ChildProcessError:
            pass
        time.sleep(0.05)


def _cmdline(pid: int) -> str:
    try:
        return Path(f"/proc/{pid}/cmdline").read_bytes().replace(b"\0", b" ").decode(errors="replace")
    except OSError:
        return ""


def _children(pid: int) -> set[int]:
    out = set()
    for d in Path("/proc").iterdir():
        if d.name.isdigit():
            try:
                stat = (d / "stat").read_text()
            except OSError:
                continue
            if int(stat.rsplit(")", 1)[1].split()[1]) == pid:
                out.add(int(d.name))
    return out


def _descendants(pid: int) -> set[int]:
    seen, todo = set(), [pid]
    while todo:
        for c in _children(todo.pop()):
            if c not in seen:
                seen.add(c)
                todo.append(c)
    return seen


class Cluster:
    def __init__(self, ns: Namespace, tmp: Path) -> None:
        self.ns, self.tmp = ns, tmp
        self.worker_raylet: int | None = None

    def ray(self, *args: str) -> None:
        ray = str(Path(sys.executable).with_name("ray"))
        done = self.ns.run([ray, *args], timeout=START_TIMEOUT)
        assert done.returncode == 0, f"ray {' '.join(args)} failed:\n{done.stdout}\n{done.stderr}"

    def driver(self, args: list[str], timeout: float = RUN_TIMEOUT, **kw) -> subprocess.Popen[str]:
        return subprocess.Popen(["ip", "netns", "exec", self.ns.name, sys.executable, *args], env=_env(),
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, **kw)


@pytest.fixture(scope="module")
def cluster() -> Iterator[Cluster]:
    if importlib.util.find_spec("ray") is None:
        _unavailable("Ray is not installed: pip install './python[ray]'")
    ns = Namespace()
    reason = ns.create()
    if reason:
        _unavailable(reason)
    # Ray's sockets and logs under a short private folder (socket paths are limited).
    tmp = Path(tempfile.mkdtemp(prefix="unfray"))
    try:
        up = ns.interfaces()
        names = [line.split(": ")[1] for line in up.splitlines() if line.strip()]
        assert names == ["lo"], f"the namespace must have only lo up:\n{up}"
        c = Cluster(ns, tmp)
        common = ["--node-ip-address=127.0.0.1", "--num-cpus=1", "--disable-usage-stats"]
        c.ray("start", "--head", f"--port={PORT}", "--include-dashboard=false", f"--temp-dir={tmp}", *common)
        head = ns.pids()
        c.ray("start", f"--address={ADDRESS}", *common)
        raylets = [p for p in ns.pids() - head if "raylet" in _cmdline(p).split(" ")[0]]
        assert len(raylets) == 1, f"one new raylet expected, found {raylets}"
        c.worker_raylet = raylets[0]
        yield c
    finally:
        ns.destroy()
        shutil.rmtree(tmp, ignore_errors=True)


def _nodes_script(out: Path) -> str:
    return (
        "import json, ray; ray.init(address=%r, log_to_driver=False); "
        "json.dump([[n['NodeManagerAddress'], n['Alive']] for n in ray.nodes()], open(%r, 'w'))" % (ADDRESS, str(out))
    )


def test_nodes_register_on_loopback(cluster: Cluster):
    out = cluster.tmp / "nodes.json"
    p = cluster.driver(["-c", _nodes_script(out)])
    _, err = p.communicate(timeout=START_TIMEOUT)
    assert p.returncode == 0, err
    nodes = json.loads(out.read_text())
    assert nodes == [["127.0.0.1", True], ["127.0.0.1", True]], nodes


FAULTS = r"""
import json, os, sys, ray
from unforeseen import _unforeseen, distributed as d
ray.init(address=sys.argv[1], log_to_driver=False)
tmp, good_map, bad_map = sys.argv[2:5]
count = os.path.join(tmp, "attempts")
plan = json.loads(_unforeseen.plan_batch({"maps": [good_map], "out": os.path.join(tmp, "plan.jsonl"),
                                          "episodes": 1, "methods": ["never-brake"], "train_seeds": [1],
                                          "train_episodes": 1}))
spec = json.loads(plan["spec"])
spec["scenarios"] = [[bad_map, bad_map]]  # the map as a node would see it: not a valid map

@ray.remote(**d._task_options(3))
def bad_input():
    with open(count, "a") as f:
        f.write("input\n")
    return d._units_task(json.dumps(spec), [], units=[0], threads=1)

@ray.remote(**d._task_options(3))
def dies_once():
    with open(count, "a") as f:
        f.write("crash\n")
    if open(count).read().count("crash") == 1:
        os._exit(1)  # the worker process dies: a system failure, retried
    return "done"

try:
    ray.get(bad_input.remote())
    result = {"raised": None}
except ray.exceptions.RayTaskError as e:
    result = {"raised": type(e.cause).__name__, "message": str(e.cause)}
result["retried"] = ray.get(dies_once.remote())
result["attempts"] = open(count).read().split()
print(json.dumps(result))
"""


def test_an_input_error_fails_once_and_a_dead_worker_is_retried(cluster: Cluster):
    bad = cluster.tmp / "bad.ron"
    bad.write_text("Map(name: \"bad\", lanes: 7)\n")
    script = cluster.tmp / "faults.py"
    script.write_text(FAULTS)
    p = cluster.driver([str(script), ADDRESS, str(cluster.tmp), str(REPO / "maps" / "jaywalk.ron"), str(bad)])
    out, err = p.communicate(timeout=RUN_TIMEOUT)
    assert p.returncode == 0, err
    result = json.loads(out.strip().splitlines()[-1])
    assert result["raised"] == "ValueError", result
    assert "bad.ron" in result["message"], result
    # The input error ran once; the crashed worker's task ran again and finished.
    assert result["attempts"] == ["input", "crash", "crash"], result
    assert result["retried"] == "done"


# A small failure search: q-learning over the shipped jaywalk space, two training seeds.
SEARCH = ["--space", str(REPO / "maps" / "spaces" / "jaywalk.ron"), "--method", "q-learning",
          "--train-seeds", "1..2", "--train-episodes", "200", "--budget", "6", "--episodes", "3", "--seed", "5",
          "--rounds", "2", "--max-failures", "2"]


def _search_outputs(out: Path) -> dict[str, object]:
    """A search folder's outputs, timing fields, the folder's name and the failure maps'
    `Found by` comment (the command that ran it) aside."""
    lines = [json.loads(line) for line in (out / "candidates.jsonl").read_text().splitlines()]
    for line in lines[1:]:
        line.pop("timing_us_per_tick")
    summary = (out / "summary.json").read_text().replace(str(out), "DIR")
    failures = {f.name: [line for line in f.read_text().replace(str(out), "DIR").splitlines()
                         if "Found by:" not in line]
                for f in sorted((out / "failures").iterdir())}
    return {"candidates": lines, "summary": json.loads(summary), "failures": failures,
            "figure": (out / "search.svg").read_text()}


def test_a_search_on_the_cluster_equals_one_machine(cluster: Cluster, tmp_path: Path):
    cli = required_cli()
    one, two = tmp_path / "one", tmp_path / "cluster"
    done = subprocess.run([str(cli), "search", *SEARCH, "--no-cache", "--quiet", "--jobs", "1", "--out", str(one)],
                          capture_output=True, text=True, timeout=RUN_TIMEOUT)
    assert done.returncode == 0, done.stderr
    driver = cluster.driver(["-m", "unforeseen.distributed", "search", *SEARCH, "--out", str(two),
                             "--candidates-per-task", "1", "--address", ADDRESS], cwd=tmp_path)
    _, err = driver.communicate(timeout=RUN_TIMEOUT)
    assert driver.returncode == 0, err
    a, b = _search_outputs(one), _search_outputs(two)
    # Every stage ran: Sobol and adaptive candidates, minimisation tries of a failure.
    counts = a["summary"]["counts"]
    assert counts["sobol"] == 3 and counts["adaptive"] == 3 and counts["minimise"] > 0, counts
    assert a["failures"], "the search should write a minimised failure"
    for part in ("candidates", "summary", "failures", "figure"):
        assert a[part] == b[part], part
    found = [line for f in (two / "failures").iterdir() for line in f.read_text().splitlines() if "Found by:" in line]
    assert found and all("python -m unforeseen.distributed search" in line for line in found)


def _lines_without_timing(path: Path) -> list[dict]:
    lines = [json.loads(line) for line in path.read_text().splitlines()]
    for line in lines[1:]:
        line.pop("timing_us_per_tick")
    return lines


def _summary_without_timing(path: Path) -> dict:
    s = json.loads(path.with_suffix(".summary.json").read_text())
    s.pop("results")
    for row in s["rows"]:
        row.pop("timing_us_per_tick")
    return s


def _wait_for(what: str, found, proc: subprocess.Popen[str], timeout: float):
    """Waits for `found()` to return something, failing when the driver ends first or
    after `timeout` seconds."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        value = found()
        if value:
            return value
        if proc.poll() is not None:
            pytest.fail(f"the driver ended before {what}:\n{proc.communicate()[1]}")
        time.sleep(0.02)
    proc.kill()
    pytest.fail(f"timed out waiting for {what}")


@pytest.fixture(scope="module")
def one_machine(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The sweep run by the command line on this machine."""
    cli = required_cli()
    one = tmp_path_factory.mktemp("one") / "one.jsonl"
    subprocess.run([str(cli), *SWEEP, "--no-cache", "--quiet", "--out", str(one)], check=False,
                   capture_output=True, timeout=RUN_TIMEOUT)
    assert one.is_file() and one.with_suffix(".summary.json").is_file()
    return one


def _lines_written(out: Path) -> int:
    try:
        return max(0, out.read_text().count("\n") - 1)
    except FileNotFoundError:
        return 0


def test_a_killed_driver_resumes_with_the_same_command(cluster: Cluster, one_machine: Path, tmp_path: Path):
    out = tmp_path / "resumed.jsonl"
    args = ["-m", "unforeseen.distributed", *SWEEP, "--out", str(out), "--units-per-task", "1", "--address", ADDRESS]
    driver = cluster.driver(args, cwd=tmp_path)
    try:
        _wait_for("the driver's first lines", lambda: _lines_written(out) >= 3, driver, RUN_TIMEOUT)
        driver.kill()
        driver.communicate(timeout=30)
    finally:
        if driver.poll() is None:
            driver.kill()
    kept = _lines_written(out)
    total = len(one_machine.read_text().splitlines()) - 1
    assert 3 <= kept < total, f"the driver should die mid-run: {kept} of {total} lines"
    again = cluster.driver([*args, "--resume"], cwd=tmp_path)
    _, err = again.communicate(timeout=RUN_TIMEOUT)
    assert again.returncode == one_code(one_machine), err
    assert _lines_without_timing(out) == _lines_without_timing(one_machine)
    assert _summary_without_timing(out) == _summary_without_timing(one_machine)


def test_a_sweep_whose_worker_node_is_killed_equals_one_machine(cluster: Cluster, one_machine: Path,
                                                                 tmp_path: Path):
    one = one_machine
    out = tmp_path / "cluster.jsonl"
    driver = cluster.driver(["-m", "unforeseen.distributed", *SWEEP, "--out", str(out), "--units-per-task", "1",
                             "--address", ADDRESS], cwd=tmp_path)
    try:
        assert cluster.worker_raylet is not None
        # Mid-run: a unit task is running on the worker node (its process is titled
        # `ray::_units_task`) and the driver has written some lines but not all.
        running = _wait_for(
            "a unit task on the worker node",
            lambda: [p for p in _descendants(cluster.worker_raylet) if _cmdline(p).startswith("ray::_units_task")],
            driver, RUN_TIMEOUT)
        assert running
        doomed = {cluster.worker_raylet, *_descendants(cluster.worker_raylet)}
        for pid in doomed:
            try:
                os.kill(pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
        written = len(out.read_text().splitlines()) - 1
        _, err = driver.communicate(timeout=RUN_TIMEOUT)
    finally:
        if driver.poll() is None:
            driver.kill()
            driver.communicate(timeout=30)
    assert driver.returncode == one_code(one), err
    cluster_lines, one_lines = _lines_without_timing(out), _lines_without_timing(one)
    assert written < len(one_lines) - 1, "the kill should come before the last unit"
    assert len(one_lines) > 20
    # The identity line and every result line (timing aside), in order; and the summary.
    assert cluster_lines == one_lines
    assert _summary_without_timing(out) == _summary_without_timing(one)
    # The worker node is dead: the head finished the run.
    nodes = tmp_path / "nodes.json"
    p = cluster.driver(["-c", _nodes_script(nodes)])
    p.communicate(timeout=START_TIMEOUT)
    assert sorted(alive for _, alive in json.loads(nodes.read_text())) == [False, True]


def one_code(one: Path) -> int:
    """The exit code `batch` gives these results: 1 when an expectation fails on the mean."""
    return 1 if json.loads(one.with_suffix(".summary.json").read_text())["failed"] else 0


class _Ref:
    """A finished task's result (hashable, as Ray's object refs are)."""

    def __init__(self, value: Any) -> None:
        self.value = value


class _InlineRay:
    """Just enough of Ray to run the driver in this process: every task runs when it is
    submitted; the names of the tasks run are kept."""

    class exceptions:  # noqa: N801 - Ray's name
        RayError = RuntimeError
        RayTaskError = RuntimeError

    def __init__(self) -> None:
        self.ran: list[str] = []

    def is_initialized(self) -> bool:
        return True

    def cluster_resources(self) -> dict[str, float]:
        return {"CPU": 1}

    def put(self, value: Any) -> _Ref:
        return _Ref(value)

    def remote(self, **_options: Any) -> Any:
        def task(f: Any) -> Any:
            def run(*args: Any, **kwargs: Any) -> _Ref:
                self.ran.append(f.__name__)
                return _Ref(f(*(a.value if isinstance(a, _Ref) else a for a in args), **kwargs))

            return types.SimpleNamespace(remote=run)

        return task

    def wait(self, refs: list[_Ref], num_returns: int, timeout: float) -> tuple[list[_Ref], list[_Ref]]:
        return refs[:num_returns], refs[num_returns:]

    def get(self, ref: Any) -> Any:
        return [r.value for r in ref] if isinstance(ref, list) else ref.value

    def cancel(self, ref: _Ref, force: bool) -> None:
        pass


def test_a_batch_of_scripted_methods_trains_no_agent_and_equals_the_command_line(tmp_path: Path, monkeypatch):
    """Issue 35, finding 12: scripted methods alone need no agent; the driver's plan
    (its identity: no agent) and lines are the command line's."""
    cli = required_cli()
    ray = _InlineRay()
    monkeypatch.setitem(sys.modules, "ray", ray)
    from unforeseen.distributed import run_batch

    args = dict(episodes=2, seed=5, methods=["never-brake", "brake-on-pedestrian"], protocol="zero-shot")
    report = run_batch(["jaywalk"], out=tmp_path / "py.jsonl", quiet=True, **args)
    assert "_train_task" not in ray.ran and "_units_task" in ray.ran
    assert [line["train_seed"] for line in report["lines"]] == [None, None]
    cli_out = tmp_path / "cli.jsonl"
    subprocess.run([str(cli), "batch", "jaywalk", "--method", "never-brake", "--method", "brake-on-pedestrian",
                    "--protocol", "zero-shot", "--episodes", "2", "--seed", "5", "-q", "--out", str(cli_out)],
                   check=True, capture_output=True, timeout=120)
    assert _lines_without_timing(tmp_path / "py.jsonl") == _lines_without_timing(cli_out)


def test_without_ray_a_run_changes_no_file(tmp_path: Path):
    """A missing Ray is refused before the output guard removes an earlier summary."""
    import importlib.util

    if importlib.util.find_spec("ray") is not None:
        pytest.skip("Ray is installed")
    import unforeseen
    from unforeseen.distributed import run_batch

    out = tmp_path / "res.jsonl"
    unforeseen.batch("jaywalk", methods=["never-brake"], episodes=1, out=out)
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir()}
    with pytest.raises(ImportError, match="needs Ray"):
        run_batch("jaywalk", methods=["never-brake"], episodes=1, out=out)
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir()} == before

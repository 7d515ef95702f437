"""The promises of the command line from Python: ``evaluate`` and ``plan_batch`` pass the
output guard of ``unforeseen batch --out`` (an input is never replaced, another
program's file needs ``force``, lines are not appended to an earlier run's); arguments
are bounded; conversions refuse recursive and over-deep values with ValueError instead
of crashing the interpreter; endless iterables are refused."""

from __future__ import annotations

import itertools
import json
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest

import unforeseen

MAPS = Path(__file__).resolve().parents[2] / "maps"


class AlwaysFast:
    method = "always-fast"

    def act(self, obs, info):
        return 1


def test_evaluate_never_writes_over_a_map_it_reads(tmp_path):
    m = tmp_path / "m.ron"
    m.write_bytes((MAPS / "jaywalk.ron").read_bytes())
    before = m.read_bytes()
    with pytest.raises(ValueError, match="would destroy"):
        unforeseen.evaluate(AlwaysFast(), [str(m)], [None], episodes=1, protocol="zero-shot", out=m)
    assert m.read_bytes() == before
    unforeseen.make_env(str(m))  # still a map


def test_evaluate_refuses_a_file_that_is_not_results_unless_forced(tmp_path):
    agent_file = tmp_path / "agent.ron"
    agent_file.write_text("(version: 1)\n")
    with pytest.raises(ValueError, match="force"):
        unforeseen.evaluate(AlwaysFast(), ["jaywalk"], [None], episodes=1, protocol="zero-shot", out=agent_file)
    assert agent_file.read_text() == "(version: 1)\n"
    unforeseen.evaluate(AlwaysFast(), ["jaywalk"], [None], episodes=1, protocol="zero-shot", out=agent_file,
                        force=True)
    assert json.loads(agent_file.read_text().splitlines()[0])["method"] == "always-fast"


def test_evaluate_twice_into_one_file_is_refused(tmp_path):
    out = tmp_path / "r.jsonl"
    unforeseen.evaluate(AlwaysFast(), ["jaywalk"], [None], episodes=1, protocol="zero-shot", out=out)
    with pytest.raises(ValueError, match="counted twice"):
        unforeseen.evaluate(AlwaysFast(), ["jaywalk"], [None], episodes=1, protocol="zero-shot", out=out)
    assert len(out.read_text().splitlines()) == 1
    assert [r["train_seeds"] for r in unforeseen.summarize(out)] == [[None]]
    # The lock was released: another method goes beside it.
    unforeseen.evaluate(AlwaysFast(), ["jaywalk"], [None], episodes=1, protocol="zero-shot", out=out,
                        method="other")
    assert len(out.read_text().splitlines()) == 2


def test_summarize_a_missing_file_is_an_error(tmp_path):
    with pytest.raises(ValueError, match="no such file"):
        unforeseen.summarize(tmp_path / "nonexistent.jsonl")


@pytest.mark.parametrize("episodes", [0, 10**7])
def test_batch_bounds_episodes(agent, episodes):
    with pytest.raises(ValueError, match="episodes"):
        unforeseen.batch("jaywalk", agents=agent, episodes=episodes, methods=["never-brake"])


def _recursive():
    x: list = []
    x.append(x)
    return x


def _deep(n: int):
    x: list = [1.0]
    for _ in range(n):
        x = [x]
    return x


@pytest.mark.parametrize("value", [_recursive(), _deep(10_000)], ids=["self-containing", "10000-deep"])
def test_recursive_and_deep_overrides_are_value_errors(value):
    with pytest.raises(ValueError, match="distance_edges"):
        unforeseen.make_env("jaywalk", distance_edges=value)
    with pytest.raises(ValueError, match="distance_edges"):
        gym.make("unforeseen/Jaywalk-v0", distance_edges=value)
    with pytest.raises(ValueError, match="distance_edges"):
        unforeseen.VectorEnv("jaywalk", num_envs=2, distance_edges=value)


def test_numpy_integers_are_override_values():
    env = unforeseen.make_env("jaywalk", max_steps=np.int64(60))
    assert env._env.max_steps == 60


def test_an_endless_observation_is_refused(agent):
    c = agent.controller("scaled")
    with pytest.raises(ValueError, match="factors"):
        c.act(itertools.count())


INTERRUPTED = """
import os, signal, sys, threading, time
import unforeseen
which = sys.argv[1]
agent = unforeseen.train("intersection", episodes=20, seed=1) if which in ("batch", "compare") else None
calls = {
    "train": lambda: unforeseen.train("intersection", episodes=1_000_000),
    "train_agents": lambda: unforeseen.train_agents([1, 2], episodes=1_000_000, cache=None),
    "batch": lambda: unforeseen.batch("jaywalk", agents=agent, episodes=1_000_000, methods=["never-brake"]),
    "compare": lambda: unforeseen.compare(agents=agent, episodes=1_000_000),
    "evaluate_builtin": lambda: unforeseen.evaluate_builtin("jaywalk", "never-brake", episodes=1_000_000),
}
threading.Timer(1.0, lambda: os.kill(os.getpid(), signal.SIGINT)).start()
start = time.monotonic()
try:
    calls[which]()
    print("finished")
except KeyboardInterrupt:
    print(f"interrupted after {time.monotonic() - start:.2f} s")
"""


@pytest.mark.parametrize("which", ["train", "train_agents", "batch", "compare", "evaluate_builtin"])
def test_long_calls_stop_on_ctrl_c(which, tmp_path):
    import os
    import subprocess
    import sys

    env = {**os.environ, "TMPDIR": str(tmp_path)}
    done = subprocess.run([sys.executable, "-c", INTERRUPTED, which], capture_output=True, text=True, env=env,
                          timeout=120)
    assert "interrupted after" in done.stdout, done.stdout + done.stderr
    seconds = float(done.stdout.split("after ")[1].split(" s")[0])
    assert seconds < 6.0, f"{which} took {seconds} s to stop after SIGINT (sent at 1 s)"
    assert not list(tmp_path.glob("unforeseen-python-batch-*")), "a temporary file was left"

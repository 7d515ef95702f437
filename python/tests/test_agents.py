"""The agents from Python: training, agent files, every method's controller, and a
Python rollout that reproduces `unforeseen eval` exactly (the library's evaluation and,
when a CLI binary is built, the command line's eval.json)."""

from __future__ import annotations

import json
import os
import subprocess
from pathlib import Path

import pytest

import unforeseen

REPO = Path(__file__).resolve().parents[2]

METHODS = [
    "q-learning", "bayes-rl", "scaled", "bayes-rl-factored", "scaled-always", "scaled-no-learning",
    "scaled-one-step-gate", "scaled-gate-learns-all", "brake-on-pedestrian", "never-brake",
]
FIELDS = ["ret", "success", "collision", "timeout", "ticks", "reasoning_ticks", "jaywalk_surprise"]


def test_train_save_load(agent, agent_file):
    assert agent.meta["episodes"] == "300" and agent.meta["map"] == "intersection"
    assert len(agent.train_returns) == 300
    loaded = unforeseen.load_agent(str(agent_file))
    assert loaded.meta == agent.meta
    assert agent_file.read_text() == agent_file.read_text()  # written whole (atomically)


@pytest.mark.parametrize("method", METHODS)
def test_every_method_drives(agent, method):
    env = unforeseen.make_env("jaywalk")
    c = agent.controller(method, epsilon=0.3, horizon=2)
    assert c.name == method
    obs, _ = env.reset(seed=0)
    c.begin_episode(0)
    action, decision = c.act(obs)
    assert action in (0, 1, 2) and decision["action"] == action
    assert set(decision) == {"action", "reasoned", "surprise", "theta", "policy", "psi", "scaling_iters"}
    assert abs(sum(decision["policy"]) - 1.0) < 1e-9
    obs, r, term, trunc, _ = env.step(action)
    c.observe(r, obs, term, trunc)
    c.end_episode()


def test_scaled_decision_record(agent):
    c = agent.controller("scaled-always")
    c.begin_episode(1)
    _, d = c.act((2, 1, 1, 1))  # a pedestrian on the crosswalk under green
    assert d["reasoned"] and d["psi"] is not None and d["surprise"] > 0 and 0 <= d["theta"] <= 1


@pytest.mark.parametrize(
    "method,protocol", [("scaled", "continual"), ("scaled", "zero-shot"), ("bayes-rl", "continual"), ("q-learning", "zero-shot")]
)
def test_python_rollout_equals_the_library_evaluation(agent, method, protocol):
    sets = ["epsilon=0.3"] if method == "scaled" else []
    py = unforeseen.rollout("jaywalk", method, episodes=6, seed=7, agent=agent, protocol=protocol, sets=sets)
    lib = unforeseen.evaluate_builtin("jaywalk", method, episodes=6, seed=7, agent=agent, protocol=protocol, sets=sets)
    assert [{k: e[k] for k in FIELDS} for e in lib["episodes"]] == py


def test_scripted_rollout_needs_no_agent():
    py = unforeseen.rollout("jaywalk", "brake-on-pedestrian", episodes=4, seed=3)
    lib = unforeseen.evaluate_builtin("jaywalk", "brake-on-pedestrian", episodes=4, seed=3)
    assert [{k: e[k] for k in FIELDS} for e in lib["episodes"]] == py
    assert all(e["success"] for e in py)


def cli_binary() -> Path | None:
    env = os.environ.get("UNFORESEEN_CLI")
    if env:
        return Path(env)
    # The most recently built of the release and debug binaries (CI builds debug).
    built = [p for p in (REPO / "target" / d / "unforeseen" for d in ("release", "debug")) if p.is_file()]
    return max(built, key=lambda p: p.stat().st_mtime, default=None)


def required_cli() -> Path:
    """The command line's binary for a test that compares against it: skipped without
    one, failed under CI (whose `cargo test` builds it)."""
    cli = cli_binary()
    if cli is None:
        if os.environ.get("CI"):
            pytest.fail("CI must build the unforeseen binary before the Python tests (cargo test does)")
        pytest.skip("no unforeseen binary: cargo build --release (or set UNFORESEEN_CLI)")
    return cli


@pytest.mark.parametrize("map_name,protocol", [("jaywalk", "continual"), ("jaywalk", "zero-shot"), ("two_pedestrians", "continual")])
def test_python_rollout_equals_the_command_line(agent_file, tmp_path, map_name, protocol):
    cli = required_cli()
    out = tmp_path / "eval"
    subprocess.run(
        [str(cli), "eval", "--agent", str(agent_file), "--map", map_name, "--method", "scaled",
         "--episodes", "5", "--seed", "9", "--protocol", protocol, "--set", "horizon=3", "--quiet",
         "--out", str(out)],
        check=True, capture_output=True,
    )
    report = json.loads((out / "eval.json").read_text())
    agent = unforeseen.load_agent(str(agent_file))
    py = unforeseen.rollout(map_name, "scaled", episodes=5, seed=9, agent=agent, protocol=protocol,
                             sets=["horizon=3"])
    assert [{k: e[k] for k in FIELDS} for e in report["episodes"]] == py
    # The figures `eval` prints are the means of those episodes.
    assert report["aggregate"]["success_rate"] == sum(e["success"] for e in py) / len(py)

"""Python policies evaluated by the library's episode loop (the Rust runner calls the
policy each tick; python/src/policy.rs): the same lines as the built-in methods, bit for
bit (timing aside), the observation the Gymnasium env gives, the episode seeds of the
policy's name, and the policy's exceptions raised as they were."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import threading
import time
from pathlib import Path

import numpy as np
import pytest

import unforeseen
from unforeseen.evaluate import evaluate_policy
from test_agents import required_cli

UNTIMED = "timing_us_per_tick"
JAYWALK = str(Path(__file__).resolve().parents[2] / "maps" / "jaywalk.ron")


class NeverBrake:
    """The scripted `never-brake` written in Python: always speed up."""

    method = "never-brake"

    def act(self, obs):
        return 1


def untimed(line):
    return {k: v for k, v in line.items() if k != UNTIMED}


def test_a_python_never_brake_gives_the_librarys_never_brake_line(agent, tmp_path):
    # The library's batch (the code `unforeseen batch` runs) and the Python policy, on the
    # same map, seed and training-seed record: the same line, every field but the clock.
    built_in = unforeseen.batch([JAYWALK], agent=agent, episodes=8, seed=3, methods=["never-brake"],
                                protocol="both", out=tmp_path / "batch.jsonl")
    [line] = built_in["lines"]
    [mine] = unforeseen.evaluate(NeverBrake(), [JAYWALK], [line["train_seed"]], episodes=8, seed=3,
                                 train_episodes=line["train_episodes"])
    assert untimed(mine) == untimed(line)
    assert mine["collision_rate"] > 0  # the jaywalker is met: the comparison covers collisions


def test_a_python_never_brake_writes_the_command_lines_never_brake_line(tmp_path):
    # The results file's bytes, up to the clock (the line's last field).
    cli = required_cli()
    out = tmp_path / "cli.jsonl"
    subprocess.run([str(cli), "batch", "jaywalk", "--method", "never-brake", "--episodes", "6", "--seed", "5",
                    "--quiet", "--out", str(out)], check=True, capture_output=True)
    [text] = [t for t in out.read_text().splitlines() if not t.startswith('{"run":')]
    line = json.loads(text)
    mine = tmp_path / "python.jsonl"
    unforeseen.evaluate(NeverBrake(), ["jaywalk"], [line["train_seed"]], episodes=6, seed=5,
                        train_episodes=line["train_episodes"], out=mine)
    [my_text] = mine.read_text().splitlines()
    clock = f',"{UNTIMED}":'
    assert text.count(clock) == 1 and text.endswith("}")
    assert my_text.split(clock)[0] == text.split(clock)[0]


def test_a_policy_under_another_name_meets_the_same_pedestrians_with_its_own_controller_seeds():
    seen = []

    class Recorder:
        method = "recorder"

        def reset(self, seed):
            seen.append(seed)

        def act(self, obs):
            return 1

    [line] = unforeseen.evaluate(Recorder(), ["jaywalk"], [None], episodes=5, seed=3, protocol="zero-shot")
    assert seen == [unforeseen.eval_seeds(3, "jaywalk", "recorder", ep)[1] for ep in range(5)]
    assert seen != [unforeseen.eval_seeds(3, "jaywalk", "never-brake", ep)[1] for ep in range(5)]
    # The world seeds are the map's: the figures are never-brake's.
    never = unforeseen.evaluate_builtin("jaywalk", "never-brake", episodes=5, seed=3)["aggregate"]
    for k in ("mean_reward", "success_rate", "collision_rate", "timeout_rate", "red_light_rate", "mean_ticks"):
        assert line[k] == never[k], k


@pytest.mark.parametrize("observation", ["discrete", "kinematic"])
def test_the_policy_sees_what_the_gymnasium_env_gives(observation):
    # A policy that brakes every third tick, recording what it saw; the same actions
    # stepped through UnforeseenEnv with the episode's world seed give the same
    # observations, dtype and all.
    seen = []

    def policy(obs):
        seen.append(obs.copy())
        return 2 if len(seen) % 3 == 0 else 1

    policy.observation = observation  # type: ignore[attr-defined]
    [episode] = evaluate_policy(policy, "jaywalk", episodes=1, seed=4, method="every-third")
    world, _ = unforeseen.eval_seeds(4, "jaywalk", "every-third", 0)
    env = unforeseen.make_env("jaywalk", observation=observation)
    obs, _ = env.reset(options={"world_seed": world})
    expected = [obs]
    for t in range(1, episode["ticks"]):
        obs, *_ = env.step(2 if t % 3 == 0 else 1)
        expected.append(obs)
    assert len(seen) == episode["ticks"] == len(expected)
    for a, b in zip(seen, expected):
        assert a.dtype == b.dtype and np.array_equal(a, b)


class Boom(Exception):
    pass


def test_an_exception_in_the_policy_surfaces_as_that_exception_and_stops_the_run():
    calls = []

    def policy(obs):
        calls.append(obs)
        if len(calls) == 3:
            raise Boom("third tick")
        return 1

    with pytest.raises(Boom, match="third tick"):
        evaluate_policy(policy, "jaywalk", episodes=50, method="boom")
    assert len(calls) == 3  # stopped at once, not at the end of the episode or the run

    class ResetFails:
        def reset(self, seed):
            raise Boom(f"reset {seed}")

        def act(self, obs):
            raise AssertionError("not reached")

    with pytest.raises(Boom, match="reset"):
        evaluate_policy(ResetFails(), "jaywalk", episodes=2, method="boom")


def test_keyboard_interrupt_in_the_policy_stops_the_evaluation():
    calls = []

    def policy(obs):
        calls.append(obs)
        if len(calls) == 5:
            raise KeyboardInterrupt
        return 1

    with pytest.raises(KeyboardInterrupt):
        evaluate_policy(policy, "jaywalk", episodes=50, method="ctrl-c")
    assert len(calls) == 5


def test_ctrl_c_stops_an_evaluation_that_calls_no_python(agent):
    # The scaled agent around its Q-table calls no Python each tick: the episodes run with
    # the GIL released (the timer's thread runs meanwhile), and the signal is seen at the
    # end of the episode it arrives in.
    timer = threading.Timer(0.5, os.kill, (os.getpid(), signal.SIGINT))
    started = time.perf_counter()
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            evaluate_policy(unforeseen.ScaledWrapper(agent=agent), "jaywalk", episodes=20_000)
    finally:
        timer.cancel()
    assert time.perf_counter() - started < 60


@pytest.mark.parametrize("answer", [3, -1, "1", 1.0, (1, {})])
def test_a_bad_action_is_refused_naming_what_the_policy_returned(answer):
    with pytest.raises(ValueError, match=r"the policy returned .*expected an action 0 \(maintain\)"):
        evaluate_policy(lambda obs: answer, "jaywalk", episodes=1, method="bad")


def test_a_habit_that_fails_surfaces_its_exception(agent):
    def habit(obs):
        raise Boom("habit")

    with pytest.raises(Boom, match="habit"):
        evaluate_policy(unforeseen.ScaledWrapper(habit=habit, agent=agent), "jaywalk", episodes=2)
    with pytest.raises(ValueError, match="sum to .*softmax"):
        evaluate_policy(unforeseen.ScaledWrapper(habit=lambda obs: [0.5, 0.6, 0.1], agent=agent), "jaywalk",
                        episodes=1)


@pytest.mark.parametrize("protocol", ["zero-shot", "continual"])
def test_the_scaled_agent_around_the_q_tables_probabilities_asked_each_tick_gives_the_scaled_line(agent, protocol, tmp_path):
    # The wrapped path: the habit is a Python callable asked each tick (the Q-table's
    # probabilities of the observed state); the line is the built-in scaled agent's.
    table = unforeseen.q_table_habit(agent)
    sizes = agent.factor_sizes

    def habit(obs):
        i = 0
        for f, n in zip(obs, sizes):
            i = i * n + int(f)
        return table[i]

    built_in = unforeseen.batch([JAYWALK], agent=agent, episodes=6, seed=7, methods=["scaled"],
                                protocol=protocol, out=tmp_path / "batch.jsonl")
    [line] = built_in["lines"]
    wrapped = unforeseen.ScaledWrapper(habit=habit, agent=agent, method="scaled")
    [mine] = unforeseen.evaluate(wrapped, [JAYWALK], [line["train_seed"]], episodes=6, seed=7, protocol=protocol,
                                 train_episodes=line["train_episodes"])
    assert line["inference_rate"] > 0  # the comparison covers reasoning ticks
    # A method given from outside is not checked against the map's expectations of the
    # built-in method it is named after (external.rs): only the checks differ.
    assert mine["checks"] == [] and line["checks"] != []
    assert untimed(mine) | {"checks": line["checks"]} == untimed(line)


def test_an_evaluation_starts_from_the_wrapper_as_built(agent):
    # Each run starts from the agent as built: what a continual run learned does not
    # reach the next evaluation (the runs are equal).
    w = unforeseen.ScaledWrapper(agent=agent, method="scaled")
    first = evaluate_policy(w, "jaywalk", episodes=4, protocol="continual")
    second = evaluate_policy(w, "jaywalk", episodes=4, protocol="continual")
    drop = ("decide_ns", "reasoning_ns")
    assert [{k: v for k, v in e.items() if k not in drop} for e in first] == \
        [{k: v for k, v in e.items() if k not in drop} for e in second]

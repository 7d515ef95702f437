"""Bad input raises ValueError with the command line's message, never a crash."""

from __future__ import annotations

import numpy as np
import pytest

import unforeseen


def test_unknown_map_name():
    with pytest.raises(ValueError, match=r"no_such_map: no such map file, and no embedded map of that name \(embedded maps: intersection"):
        unforeseen.make_env("no_such_map")


def test_broken_map_file_names_file_line_and_fix(tmp_path):
    bad = tmp_path / "broken.ron"
    bad.write_text('(\n    base: "jaywalk",\n    road: (lane_width: -3.0),\n)\n')
    with pytest.raises(ValueError, match=r"broken.ron:3:12: road.lane_width: .*") as e:
        unforeseen.make_env(str(bad))
    syntax = tmp_path / "syntax.ron"
    syntax.write_text('(\n    base: "jaywalk",\n    road: (lane_width: 3.0\n')
    with pytest.raises(ValueError, match=r"syntax.ron:\d+:\d+: "):
        unforeseen.make_env(str(syntax))
    assert "lane_width" in str(e.value)


def test_bad_action():
    env = unforeseen.make_env("jaywalk")
    env.reset(seed=0)
    for bad in (3, -1, 99):
        with pytest.raises(ValueError, match=rf"action {bad} is not one of 0 \(maintain\), 1 \(speed up\), 2 \(slow down\)"):
            env.step(bad)
    env.step(0)  # the env is unchanged and still runs
    with pytest.raises(TypeError):
        env.step(1.5)  # not truncated to 1
    env.step(np.int64(1))  # numpy integers are actions


def test_step_out_of_order():
    env = unforeseen.make_env("jaywalk")
    with pytest.raises(RuntimeError, match="before reset"):
        env.step(0)


def test_bad_parameters(agent):
    # Keyword arguments are named as the settings they are, not as the command line's flag.
    with pytest.raises(ValueError, match="^epsilon=abc: parameter `epsilon` = abc is invalid: 'abc' is not a number; must be in \\[0, 1\\)") as e:
        agent.controller("scaled", epsilon="abc")
    assert "--set" not in str(e.value)
    with pytest.raises(ValueError, match="^no_such: unknown parameter `no_such`; known: .*epsilon"):
        agent.controller("scaled", no_such=1)
    with pytest.raises(ValueError, match="^epsilon=7.0: parameter `epsilon`"):
        agent.controller("scaled", epsilon=7.0)
    with pytest.raises(ValueError, match="^horizon"):
        agent.controller("scaled", horizon=2.5)
    with pytest.raises(ValueError, match="expected a number, a bool or a string"):
        agent.controller("scaled", epsilon=[0.1])


def test_typed_parameters_go_through_the_parameter_table(agent):
    # Numbers, bools, inf and text all reach the same table as `--set`.
    agent.controller("scaled", epsilon=0.3, horizon=4, learning=False, gate_memory=float("inf"))
    agent.controller("scaled", scaling_mode="closed-form", epsilon="0.25")
    with pytest.raises(ValueError, match="unknown method 'nope'; methods: q-learning"):
        agent.controller("nope")
    with pytest.raises(ValueError, match="observation"):
        agent.controller("scaled").act(10_000)
    with pytest.raises(ValueError, match="observation"):
        unforeseen.make_env("jaywalk", observation="pixels")


def test_bad_agent_file(tmp_path):
    bad = tmp_path / "agent.ron"
    bad.write_text("(not an agent)")
    with pytest.raises(ValueError, match=r"agent.ron: .*retrain it with `unforeseen train --out"):
        unforeseen.load_agent(str(bad))
    with pytest.raises(ValueError, match="cannot read the agent file"):
        unforeseen.load_agent(str(tmp_path / "missing.ron"))


@pytest.mark.parametrize(
    "call,message",
    [
        (lambda: unforeseen.make_env("jaywalk", offset="(((("), r"jaywalk \(overrides\):\d+:\d+: "),
        (lambda: unforeseen.make_env("jaywalk", max_steps=10**12), "episode.max_steps"),
        (lambda: unforeseen.make_env("jaywalk", lane_width=float("nan")), "road.lane_width: must be a finite number"),
        (lambda: unforeseen.make_env("jaywalk", distance_edges=[60, 30]), "strictly increasing"),
        (lambda: unforeseen.make_env("jaywalk", cycle=[]), "light.cycle"),
        (lambda: unforeseen.make_env("jaywalk", pedestrian_slots=0), "pedestrian_slots 0: expected a whole number in 1..=100"),
        (lambda: unforeseen.make_env("/dev/null"), "not a regular file"),
        (lambda: unforeseen.VectorEnv("jaywalk", 2, num_threads=0), "num_threads 0"),
        (lambda: unforeseen.train(episodes=0), "episodes 0"),
        (lambda: unforeseen.scripted_controller("scaled"), "needs a trained agent"),
        (lambda: unforeseen.evaluate_builtin("jaywalk", "scaled", episodes=2, agent="no-such-agent.ron"),
         "no-such-agent.ron"),
        (lambda: unforeseen.evaluate_builtin("jaywalk", "never-brake", episodes=2, protocol="x"), "^protocol: "),
        (lambda: unforeseen.evaluate_builtin("jaywalk", "never-brake", episodes=0), "^episodes"),
        (lambda: unforeseen.compare(agents=[]), "at least one agent"),
        (lambda: unforeseen.compare(protocol="twice"), "^protocol: "),
        (lambda: unforeseen.compare(sets=["epsilon=2"]), "epsilon"),
    ],
)
def test_bad_input_raises_value_error_never_a_panic(call, message):
    with pytest.raises(ValueError, match=message):
        call()


def test_controllers_refuse_nan_rewards_and_bool_observations(agent):
    """`observe(nan, ...)` and `act([True, False, True, True])` were accepted: a NaN
    reward poisons what test-time learning keeps, and a bool is not a factor's value."""
    wrapped = unforeseen.ScaledWrapper(agent=agent)
    info = {"observed": (3, 0, 1, 0)}
    controller = agent.controller("scaled")
    controller.begin_episode(1)
    wrapped.begin_episode(1)
    controller.act((3, 0, 1, 0))
    wrapped.act(None, info)
    for reward in (float("nan"), float("inf"), -float("inf")):
        with pytest.raises(ValueError, match=r"reward .*: expected a finite number"):
            controller.observe(reward, (3, 0, 1, 0), False, False)
        with pytest.raises(ValueError, match=r"reward .*: expected a finite number"):
            wrapped.observe(reward, None, info, False, False)
    for observed in (True, [True, False, True, True]):
        with pytest.raises(ValueError, match=r"observation"):
            controller.act(observed)
        with pytest.raises(ValueError, match=r"observation"):
            wrapped.act(None, {"observed": observed})
    controller.observe(-4.5, (3, 1, 1, 0), False, False)  # still usable
    wrapped.observe(-4.5, None, {"observed": (3, 1, 1, 0)}, False, False)


def test_a_habit_array_of_the_wrong_shape_says_what_shape_is_wanted(agent):
    n_states = int(np.prod(agent.factor_sizes))
    with pytest.raises(ValueError, match=rf"habit: an array of shape \(192,\); a habit table is \(n_states, n_actions\) = \({n_states}, 3\)"):
        unforeseen.ScaledWrapper(habit=np.ones(192) / 3, agent=agent)

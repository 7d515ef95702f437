"""Every count, seed and size argument of every public function, table-driven: a value it
cannot take (negative, zero where the count starts at one, a float, a bool, text, a
huge int, NaN or inf) raises the same ``ValueError``, naming the argument and its range,
before any work; a numpy integer is an integer."""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np
import pytest

import unforeseen
from unforeseen import _unforeseen

SEEDS = "0..=18446744073709551615"
EPISODES = "1..=1000000"
EPISODE_INDEX = "0..=18446744073709551615"


class _Brake:
    """A policy that always slows down."""

    method = "always-brake"

    def act(self, obs: Any) -> int:
        return 2


def _search(**kw: Any) -> Any:
    return unforeseen.search("maps/spaces/no-such-space.ron", method="never-brake", **kw)


#: (the call with the value in place, the field its error names, the field's range).
ARGUMENTS: list[tuple[str, Callable[[Any], Any], str, str]] = [
    ("train.episodes", lambda v: unforeseen.train(episodes=v), "episodes", EPISODES),
    ("train.seed", lambda v: unforeseen.train(episodes=1, seed=v), "seed", SEEDS),
    ("train_agents.seeds", lambda v: unforeseen.train_agents([v], episodes=1), r"seeds\[0\]", SEEDS),
    ("train_agents.episodes", lambda v: unforeseen.train_agents([1], episodes=v), "episodes", EPISODES),
    ("evaluate_builtin.episodes",
     lambda v: unforeseen.evaluate_builtin(method="never-brake", episodes=v, out=None), "episodes", EPISODES),
    ("evaluate_builtin.seed",
     lambda v: unforeseen.evaluate_builtin(method="never-brake", episodes=1, seed=v, out=None), "seed", SEEDS),
    ("rollout.episodes", lambda v: unforeseen.rollout(method="never-brake", episodes=v), "episodes", EPISODES),
    ("rollout.seed", lambda v: unforeseen.rollout(method="never-brake", episodes=1, seed=v), "seed", SEEDS),
    ("compare.episodes", lambda v: unforeseen.compare(episodes=v, out=None, cache=None), "episodes", EPISODES),
    ("compare.train_episodes",
     lambda v: unforeseen.compare(train_episodes=v, out=None, cache=None), "train_episodes", EPISODES),
    ("compare.seed", lambda v: unforeseen.compare(seed=v, out=None, cache=None), "seed", SEEDS),
    ("compare.train_seeds",
     lambda v: unforeseen.compare(train_seeds=[1, v], out=None, cache=None), r"train_seeds\[1\]", SEEDS),
    ("batch.episodes", lambda v: unforeseen.batch("jaywalk", methods=["never-brake"], episodes=v), "episodes",
     EPISODES),
    ("batch.seed", lambda v: unforeseen.batch("jaywalk", methods=["never-brake"], seed=v), "seed", SEEDS),
    ("batch.jobs", lambda v: unforeseen.batch("jaywalk", methods=["never-brake"], jobs=v), "jobs", "1..=256"),
    ("batch.train_episodes",
     lambda v: unforeseen.batch("jaywalk", train_seeds=[1], train_episodes=v, cache=None), "train_episodes",
     EPISODES),
    # The conversion's bound is the larger of the search's (65536) and the estimate's;
    # each job's own is the library's.
    ("search.budget", lambda v: _search(budget=v), "budget", "1..=1000000"),
    ("estimate.budget", lambda v: unforeseen.estimate("maps/spaces/no-such-space.ron", method="never-brake", budget=v),
     "budget", "1..=1000000"),
    ("search.episodes", lambda v: _search(episodes=v), "episodes", EPISODES),
    ("search.seed", lambda v: _search(seed=v), "seed", SEEDS),
    ("search.jobs", lambda v: _search(jobs=v), "jobs", "1..=256"),
    ("search.rounds", lambda v: _search(rounds=v), "rounds", "0..=18446744073709551615"),
    ("search.max_failures", lambda v: _search(max_failures=v), "max_failures", "0..=18446744073709551615"),
    ("evaluate.episodes", lambda v: unforeseen.evaluate(_Brake(), ["jaywalk"], [None], episodes=v), "episodes",
     EPISODES),
    ("evaluate.seed", lambda v: unforeseen.evaluate(_Brake(), ["jaywalk"], [None], episodes=1, seed=v), "seed",
     SEEDS),
    ("evaluate.seeds", lambda v: unforeseen.evaluate(_Brake(), ["jaywalk"], [v], episodes=1), r"seeds\[0\]",
     SEEDS),
    ("evaluate.train_episodes",
     lambda v: unforeseen.evaluate(_Brake(), ["jaywalk"], [1], episodes=1, train_episodes=v), "train_episodes",
     EPISODES),
    ("evaluate_policy.episodes", lambda v: unforeseen.evaluate_policy(_Brake(), "jaywalk", episodes=v),
     "episodes", EPISODES),
    ("evaluate_policy.seed", lambda v: unforeseen.evaluate_policy(_Brake(), "jaywalk", episodes=1, seed=v),
     "seed", SEEDS),
    ("eval_seeds.seed", lambda v: unforeseen.eval_seeds(v, "jaywalk", "scaled", 0), "seed", SEEDS),
    ("eval_seeds.episode", lambda v: unforeseen.eval_seeds(7, "jaywalk", "scaled", v), "episode", EPISODE_INDEX),
    ("stream_seed.key", lambda v: unforeseen.stream_seed(v, 0), "key", SEEDS),
    ("stream_seed.episode", lambda v: unforeseen.stream_seed(1, v), "episode", EPISODE_INDEX),
    ("make_env.pedestrian_slots", lambda v: unforeseen.UnforeseenEnv("jaywalk", pedestrian_slots=v),
     "pedestrian_slots", "1..=100"),
    ("reset.world_seed", lambda v: unforeseen.make_env().reset(options={"world_seed": v}), "world_seed", SEEDS),
    ("VectorEnv.num_envs", lambda v: unforeseen.VectorEnv("jaywalk", v), "num_envs", "1..=65536"),
    ("VectorEnv.num_threads", lambda v: unforeseen.VectorEnv("jaywalk", 2, num_threads=v), "num_threads",
     "1..=1024"),
    ("rust_loop.steps", lambda v: _unforeseen.rust_loop("jaywalk", [0], v), "steps", "0..=18446744073709551615"),
    ("rust_loop.seed", lambda v: _unforeseen.rust_loop("jaywalk", [0], 1, v), "seed", SEEDS),
]

#: Values no count, seed or size takes, by kind.
BAD = {
    "negative": -5,
    "float": 2.5,
    "whole float": 3.0,
    "bool": True,
    "text": "5",
    "huge": 2**70,
    "nan": math.nan,
    "inf": math.inf,
}


def _cases() -> list[Any]:
    cases = []
    for name, call, field, range_ in ARGUMENTS:
        values = dict(BAD)
        if range_.startswith("1.."):
            values["zero"] = 0
        for kind, value in values.items():
            cases.append(pytest.param(call, value, field, range_, id=f"{name}-{kind}"))
    return cases


@pytest.mark.parametrize("call,value,field,range_", _cases())
def test_a_value_out_of_range_or_of_another_type_names_the_argument_and_its_range(call, value, field, range_):
    with pytest.raises(ValueError) as e:
        call(value)
    message = str(e.value)
    assert message.startswith(field.replace("\\", "")), message
    assert range_ in message, message


def test_numpy_integers_are_integers(agent):
    i = np.int64
    assert unforeseen.stream_seed(i(3), np.uint32(2)) == unforeseen.stream_seed(3, 2)
    assert unforeseen.eval_seeds(i(7), "jaywalk", "scaled", i(1)) == unforeseen.eval_seeds(7, "jaywalk", "scaled", 1)
    env = unforeseen.UnforeseenEnv("jaywalk", pedestrian_slots=i(2))
    env.reset(options={"world_seed": i(4)})
    vec = unforeseen.VectorEnv("jaywalk", i(2), num_threads=np.int32(1))
    assert vec.num_envs == 2
    vec.reset(seed=[i(1), i(2)])
    assert _unforeseen.rust_loop("jaywalk", [0], i(3), i(1))[0] == 3
    unforeseen.train(episodes=i(1), seed=i(2))
    unforeseen.train_agents([i(1)], episodes=i(1), cache=None)
    assert len(unforeseen.evaluate_policy(_Brake(), "jaywalk", episodes=i(2), seed=i(1))) == 2
    assert len(unforeseen.evaluate(_Brake(), ["jaywalk"], [i(1)], episodes=i(1), seed=i(3),
                                   train_episodes=i(10))) == 1
    report = unforeseen.evaluate_builtin(method="never-brake", episodes=i(2), seed=i(3), out=None)
    assert len(report["episodes"]) == 2
    result = unforeseen.batch("jaywalk", methods=["never-brake"], episodes=i(1), seed=i(3), jobs=i(1))
    assert len(result["lines"]) == 1


@pytest.mark.parametrize(
    "call,message",
    [
        (lambda: unforeseen.train_agents(list(range(1001)), episodes=1), r"^seeds: 1001 seeds; at most 1000"),
        (lambda: unforeseen.train_agents([1, 1], episodes=1), r"^seeds: seed 1 is listed twice"),
        (lambda: unforeseen.train_agents([], episodes=1), r"^seeds: "),
        (lambda: unforeseen.compare(train_seeds=2**70, out=None), r"^train_seeds 1180591620717411303424: "),
        (lambda: unforeseen.compare(train_seeds=[1, [2]], out=None), r"^train_seeds\[1\] \[2\]: expected a whole number"),
        (lambda: unforeseen.batch("jaywalk", out=""), r"^out: an empty path"),
        (lambda: unforeseen.batch("jaywalk", cache=""), r"^cache: an empty path"),
        (lambda: unforeseen.compare(out="", cache=None), r"^out: an empty path"),
        (lambda: unforeseen.evaluate(_Brake(), ["jaywalk"], [None], out=""), r"^out: an empty path"),
        (lambda: unforeseen.evaluate(_Brake(), ["jaywalk", "jaywalk"], [None], episodes=1),
         r"^maps: .*list each map once"),
        (lambda: unforeseen.evaluate(_Brake(), ["jaywalk"], [1, 1], episodes=1), r"^seeds: 1 is listed twice"),
        (lambda: unforeseen.evaluate(_Brake(), ["jaywalk"], [None], method="a\nb", episodes=1), r'^method "a\\nb": has a control'),
        (lambda: unforeseen.evaluate_builtin(sets=["epsilon=nan"], out=None), r"epsilon"),
        (lambda: unforeseen.batch("jaywalk", sets=[float("nan")]), r"^sets\[0\] nan: expected text"),
        (lambda: unforeseen.make_env(max_steps="40"), r"^map override max_steps: '40' is not a whole number"),
        (lambda: unforeseen.make_env(max_steps=True), r"^map override max_steps: True is not a whole number"),
        (lambda: unforeseen.make_env(max_steps=40.5), r"^map override max_steps: 40.5 is not a whole number"),
        (lambda: unforeseen.make_env(max_steps=float("nan")), r"^map override max_steps: nan is not a whole number"),
        (lambda: unforeseen.UnforeseenEnv("jaywalk", pedestrian_slots=-1), r"^pedestrian_slots -1: expected a whole number in 1..=100"),
        (lambda: unforeseen.VectorEnv("jaywalk", 3).reset(seed="a"), r"^seed 'a': expected an int, a sequence of 3"),
        (lambda: unforeseen.train(map=""), r"^map: an empty path"),
    ],
)
def test_nonsense_is_refused_naming_the_argument(call, message):
    with pytest.raises(ValueError, match=message):
        call()


def test_paths_are_maps():
    # A pathlib.Path is a map file wherever a map is taken.
    from conftest import REPO

    path = REPO / "maps" / "intersection.ron"
    assert isinstance(unforeseen.train(map=path, episodes=1), unforeseen.Agent)
    assert unforeseen.eval_seeds(7, path, "scaled", 0) == unforeseen.eval_seeds(7, str(path), "scaled", 0)
    unforeseen.UnforeseenEnv(path).reset(seed=1)


def test_a_misspelt_keyword_of_the_wrapper_is_named_as_one(agent):
    with pytest.raises(TypeError, match=r"unexpected keyword argument 'agnt'; did you mean 'agent'\?"):
        unforeseen.ScaledWrapper(agnt=agent)
    with pytest.raises(TypeError, match=r"'observaton'; did you mean 'observation'\?"):
        unforeseen.ScaledWrapper(agent=agent, observaton="discrete")
    # A parameter's own name is a parameter (the table checks it).
    assert unforeseen.ScaledWrapper(agent=agent, horizon=2).method == "scaled-wrapper"

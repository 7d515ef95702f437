"""The four ways the Python front once disagreed with the command line (issue 33, "the
drift users meet"), one test each. Each failed before its fix; the fixes build the value
in the Rust harness, once, for both fronts, so the drift cannot come back:

1. ``ScaledWrapper(agent=..., learning=False)`` reported that it learns across episodes
   (it read a key ``learning_enabled`` the parameters do not have); the wrapper now asks
   the library (``Method::learns_across_episodes``).
2. compare.json from Python lacked ``red_light_rate`` on the paper rows (and had no
   ``columns``); both fronts now call ``CompareReport::new``.
3. eval.json from Python had no ``train_seed``; both fronts now call ``evaluate_map``.
4. ``rollout`` built brake-on-pedestrian without the map's red-light rule, which
   ``evaluate_builtin`` and the command line honour; a scripted controller can now only be
   built for a map (``Method::scripted_controller(sizes, map)``).
"""

from __future__ import annotations

from pathlib import Path

import pytest

import unforeseen
from unforeseen import ScaledWrapper

REPO = Path(__file__).resolve().parents[2]

FIELDS = ["ret", "success", "collision", "timeout", "ticks", "reasoning_ticks", "jaywalk_surprise"]
RED_LIGHT_MAP = str(REPO / "maps" / "red_light" / "red_on_approach.ron")


def test_1_a_wrapper_told_not_to_learn_does_not_learn_across_episodes(agent):
    assert ScaledWrapper(agent=agent).learns is True
    assert ScaledWrapper(agent=agent, learning=False).learns is False
    # So evaluate runs it once, for both protocols, as a method that does not learn.
    lines = unforeseen.evaluate(lambda s: ScaledWrapper(agent=agent, learning=False), ["jaywalk"], [7],
                                episodes=2, protocol=["zero-shot", "continual"], method="scaled+q")
    assert [(l["protocol"], l["covers"]) for l in lines] == [("zero-shot", ["zero-shot", "continual"])]


def test_2_compare_json_from_python_has_the_command_lines_paper_rows_and_columns(agent):
    report = unforeseen.compare(agents=agent, episodes=2, protocol="zero-shot")
    assert [p["method"] for p in report["paper"]] == ["q-learning", "bayes-rl", "scaled"]
    for row in report["paper"]:
        assert "red_light_rate" in row and row["red_light_rate"] is None, row
        assert row["collision_rate"] is None
    assert set(report["columns"]) >= {"train_reward", "test_reward", "success_rate", "red_light_rate"}


def test_3_eval_json_from_python_names_the_agents_training_seed(agent):
    report = unforeseen.evaluate_builtin("jaywalk", "scaled", episodes=2, seed=7, agent=agent)
    assert report["train_seed"] == "7"
    scripted = unforeseen.evaluate_builtin("jaywalk", "never-brake", episodes=1)
    assert "train_seed" in scripted and scripted["train_seed"] is None


@pytest.mark.parametrize("with_agent", [False, True])
def test_4_python_rollout_of_brake_on_pedestrian_stops_for_red_as_the_library_does(agent, with_agent):
    a = agent if with_agent else None
    py = unforeseen.rollout(RED_LIGHT_MAP, "brake-on-pedestrian", episodes=4, seed=3, agent=a)
    lib = unforeseen.evaluate_builtin(RED_LIGHT_MAP, "brake-on-pedestrian", episodes=4, seed=3, agent=a)
    assert [{k: e[k] for k in FIELDS} for e in lib["episodes"]] == py
    assert lib["aggregate"]["red_light_rate"] == 0.0, "the witness stops for red on this map"

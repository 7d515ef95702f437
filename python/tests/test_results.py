"""compare and batch from Python return the data of their JSON files."""

from __future__ import annotations

import pytest

import unforeseen


def test_compare(agent):
    report = unforeseen.compare(agents=agent, episodes=3, protocol="zero-shot")
    assert report["schema"] == 2 and report["protocols"] == ["zero-shot"]
    (table,) = report["tables"]
    assert [m["method"] for m in table["methods"]] == ["q-learning", "bayes-rl", "scaled"]
    assert report["train_seeds"] == [7] and report["episodes"] == 3


def test_batch_with_a_sweep(agent, tmp_path):
    out = unforeseen.batch("jaywalk", agent=agent, episodes=2, methods=["scaled", "never-brake"],
                           protocol="zero-shot", sets=["horizon=1,2"], out=tmp_path / "r.jsonl")
    lines = out["lines"]
    assert {(l["method"], l["param_set"]) for l in lines} >= {("scaled", "horizon=1"), ("scaled", "horizon=2")}
    assert out["summary"]
    with pytest.raises(ValueError, match="^methods: unknown variant `nope`"):
        unforeseen.batch("jaywalk", agent=agent, methods=["nope"], out=tmp_path / "r.jsonl")


def test_train_agents_trains_each_seed_once_and_caches_them(tmp_path):
    cache = tmp_path / "agents"
    agents = unforeseen.train_agents([3, 4], episodes=60, cache=str(cache))
    assert [a.meta["seed"] for a in agents] == ["3", "4"]
    assert len(list(cache.iterdir())) == 2
    # From the cache: the same agents; and the same as training one seed alone.
    again = unforeseen.train_agents([3, 4], episodes=60, cache=str(cache))
    assert [a.meta for a in again] == [a.meta for a in agents]
    one = unforeseen.train("intersection", episodes=60, seed=3)
    table = unforeseen.compare(agents=[agents[0]], episodes=3, protocol="zero-shot")
    again_table = unforeseen.compare(agents=[one], episodes=3, protocol="zero-shot")
    rows = lambda t: [(m["method"], m["per_seed"][0]["test_reward"], m["per_seed"][0]["success_rate"]) for m in t["tables"][0]["methods"]]
    assert [r[0] for r in rows(table)] == ["q-learning", "bayes-rl", "scaled"]
    assert rows(table) == rows(again_table), "seed 3 from train_agents is seed 3 of train"
    with pytest.raises(ValueError, match="timeout_as"):
        unforeseen.train_agents([1], episodes=10, cache=None, timeout_as="never")

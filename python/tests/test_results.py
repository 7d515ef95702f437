"""compare and batch from Python return the data of their JSON files."""

from __future__ import annotations

import pytest

import unforeseen


def test_compare(agent):
    report = unforeseen.compare(agents=agent, episodes=3, protocols=["zero-shot"])
    assert report["schema"] == 2 and report["protocols"] == ["zero-shot"]
    (table,) = report["tables"]
    assert [m["method"] for m in table["methods"]] == ["q-learning", "bayes-rl", "scaled"]
    assert report["train_seeds"] == [7] and report["episodes"] == 3


def test_batch_with_a_sweep(agent):
    out = unforeseen.batch("jaywalk", agents=agent, episodes=2, methods=["scaled", "never-brake"],
                           protocols=["zero-shot"], sweep={"horizon": [1, 2]})
    lines = out["lines"]
    assert {(l["method"], l["param_set"]) for l in lines} >= {("scaled", "horizon=1"), ("scaled", "horizon=2")}
    assert out["summary"]
    with pytest.raises(ValueError, match="unknown method"):
        unforeseen.batch("jaywalk", agents=agent, methods=["nope"])

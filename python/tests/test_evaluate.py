"""unforeseen.evaluate: any Python policy on our maps, written as batch result lines
that the batch summary (the Rust code `unforeseen batch` uses) and `unforeseen
plot-sweep` read beside the built-in methods."""

from __future__ import annotations

import subprocess

import pytest

import unforeseen
from test_agents import required_cli


class AlwaysFast:
    """Speeds up whatever it sees."""

    method = "always-fast"
    observation = "kinematic"

    def act(self, obs):
        return 1


def test_lines_are_read_by_the_batch_summary_beside_builtin_methods(agent, tmp_path):
    out = tmp_path / "results.jsonl"
    builtin = unforeseen.batch("jaywalk", agent=agent, episodes=4, seed=7, methods=["q-learning"],
                               protocol="zero-shot", out=tmp_path / "builtin.jsonl")
    # The batch's own file, its lines beside which the policy's go.
    out.write_bytes((tmp_path / "builtin.jsonl").read_bytes())
    assert len(builtin["lines"]) == 1
    lines = unforeseen.evaluate({3: AlwaysFast(), 4: AlwaysFast()}, ["jaywalk", "intersection"], [3, 4],
                                episodes=5, protocol=["zero-shot", "continual"], out=out, append=True)
    assert [(l["scenario"], l["train_seed"]) for l in lines] == [("jaywalk", 3), ("jaywalk", 4),
                                                                 ("intersection", 3), ("intersection", 4)]
    # A policy that does not learn runs once and covers both protocols, as the batch does.
    assert all(l["covers"] == ["zero-shot", "continual"] for l in lines)
    rows = unforeseen.summarize(out)
    by = {(r["scenario"], r["method"]): r for r in rows}
    assert set(by) == {("jaywalk", "q-learning"), ("jaywalk", "always-fast"), ("intersection", "always-fast")}
    row = by[("jaywalk", "always-fast")]
    assert row["train_seeds"] == [3, 4]
    # Never braking meets the jaywalker: no success, all collisions, on both seeds.
    assert row["success_rate"]["mean"] == 0.0 and row["collision_rate"]["mean"] == 1.0
    assert row["worst_seed"]["success_rate"] == 0.0
    assert by[("intersection", "always-fast")]["success_rate"]["mean"] > 0.5


def test_plot_sweep_reads_the_lines(tmp_path):
    cli = required_cli()
    out = tmp_path / "results.jsonl"
    unforeseen.evaluate(AlwaysFast(), ["jaywalk"], [None], episodes=3, protocol="zero-shot", out=out)
    subprocess.run([str(cli), "plot-sweep", str(out), "--out", str(tmp_path / "sweep.svg")],
                   check=True, capture_output=True)
    assert (tmp_path / "sweep.svg").stat().st_size > 0


def test_a_learning_policy_gets_one_line_per_protocol(agent):
    lines = unforeseen.evaluate(lambda s: unforeseen.ScaledWrapper(agent=agent), ["jaywalk"], [7],
                                episodes=3, protocol=["zero-shot", "continual"], method="scaled+q")
    assert [(l["protocol"], l["covers"]) for l in lines] == [("zero-shot", ["zero-shot"]), ("continual", ["continual"])]
    assert all(0 < l["inference_rate"] <= 1 and l["efe_matvecs_per_tick"] > 0 for l in lines)


def test_bad_arguments_say_what_to_fix():
    with pytest.raises(ValueError, match="protocol 'both'"):
        unforeseen.evaluate(AlwaysFast(), ["jaywalk"], [None], episodes=1, protocol="both")
    with pytest.raises(ValueError, match="at least one"):
        unforeseen.evaluate(AlwaysFast(), [], [None], episodes=1)
    with pytest.raises(ValueError, match="name the method"):
        unforeseen.evaluate(lambda s: type("P", (), {"act": lambda self, o: 0})(), ["jaywalk"], [None], episodes=1)
    with pytest.raises(ValueError, match="episodes 0"):
        unforeseen.evaluate(AlwaysFast(), ["jaywalk"], [None], episodes=0)

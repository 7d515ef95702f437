"""compare, eval and batch results print as the command line's tables: ``str(result)`` is
what the command line prints for the same request (the binary's stdout, timing masked),
and notebooks get the same table as Markdown and HTML."""

from __future__ import annotations

import json
import re
import subprocess
import sys

import pytest

import unforeseen
from unforeseen import _unforeseen
from conftest import REPO
from test_agents import required_cli


def cli(*args: str) -> str:
    """The command line's stdout for ``args``, without its last line (``wrote ...``)."""
    binary = required_cli()
    out = subprocess.run([str(binary), *args], check=True, capture_output=True, text=True).stdout
    lines = out.rstrip("\n").split("\n")
    assert lines[-1].startswith("wrote "), out
    return "\n".join(lines[:-1])


def untimed(text: str) -> str:
    """``text`` with the wall-clock figures masked: eval's µs/tick, and the last cell of
    compare's rows (µs/tick) where a line ends in a number."""
    text = re.sub(r"[0-9.]+ µs/tick", "T µs/tick", text)
    return "\n".join(re.sub(r" +[0-9.]+( ± [0-9.]+)?$", " T", line) for line in text.split("\n"))


def test_compare_prints_the_command_lines_tables(agent_file, tmp_path):
    printed = cli("compare", "--agent", str(agent_file), "--episodes", "3", "--protocol", "both",
                  "--set", "horizon=2", "--quiet", "--out", str(tmp_path / "c"))
    agent = unforeseen.load_agent(str(agent_file))
    result = unforeseen.compare(agents=agent, episodes=3, protocol="both", sets=["horizon=2"])
    assert isinstance(result, unforeseen.CompareResult)
    assert untimed(str(result)) == untimed(printed)
    assert "== zero-shot protocol" in str(result) and "== continual protocol" in str(result)
    assert repr(result) == str(result)


def test_eval_prints_the_command_lines_line(agent_file, tmp_path):
    printed = cli("eval", "--agent", str(agent_file), "--map", "two_pedestrians", "--method", "scaled",
                  "--episodes", "4", "--seed", "9", "--protocol", "continual", "--quiet", "--out", str(tmp_path / "e"))
    agent = unforeseen.load_agent(str(agent_file))
    result = unforeseen.evaluate_builtin("two_pedestrians", "scaled", episodes=4, seed=9, agent=agent,
                                         protocol="continual")
    assert isinstance(result, unforeseen.EvalResult)
    assert untimed(str(result)) == untimed(printed)
    scripted = unforeseen.evaluate_builtin("jaywalk", "never-brake", episodes=2)
    assert "never-brake does not learn across episodes" in str(scripted)


def test_batch_prints_the_command_lines_summary_byte_for_byte(agent_file, tmp_path):
    maps = [str(REPO / "maps" / "jaywalk.ron"), str(REPO / "maps" / "crowd.ron")]
    printed = cli("batch", *maps, "--agent", str(agent_file), "--episodes", "2", "--method", "scaled",
                  "--method", "never-brake", "--protocol", "both", "--quiet", "--out", str(tmp_path / "b.jsonl"))
    agent = unforeseen.load_agent(str(agent_file))
    result = unforeseen.batch(maps, agent=agent, episodes=2, methods=["scaled", "never-brake"],
                              out=tmp_path / "lib.jsonl")
    assert isinstance(result, unforeseen.BatchResult)
    # No wall-clock figure in the batch's table: the same bytes.
    assert str(result) == printed
    assert [r["method"] for r in result.summary] == [r["method"] for r in result["summary"]]
    assert len(result.lines) == len(result["lines"]) == 6  # scaled under both protocols, never-brake once, 2 maps


def test_markdown_and_html_show_the_same_table(agent):
    result = unforeseen.compare(agents=agent, episodes=2, protocol="both")
    md = result._repr_markdown_()
    assert "#### zero-shot protocol" in md and "#### continual protocol" in md
    # The two header lines joined into one header cell per column.
    assert "| method | train reward (intersection) | test reward (jaywalk) |" in md
    assert "|:---|---:|" in md
    # Markdown's specials escaped: the mark of a method run once.
    assert "| q-learning\\* |" in md
    html = result._repr_html_()
    assert html.count("<table>") == 2 and html.count("<thead>") == 2
    assert '<th style="text-align: left">method</th>' in html
    for row in result.to_records():
        assert f'<td style="text-align: left">{row["method"]}' in html
    evaluated = unforeseen.evaluate_builtin("jaywalk", "never-brake", episodes=2)
    assert evaluated._repr_markdown_().strip() == str(evaluated)
    assert evaluated._repr_html_().startswith("<div>\n<p>never-brake on 'jaywalk' (zero-shot; ")


def test_the_data_keeps_its_keys(agent):
    result = unforeseen.compare(agents=agent, episodes=2, protocol="zero-shot")
    data = result.to_dict()
    assert sorted(data) == result.keys()
    assert result["tables"] == data["tables"] == result.tables
    assert "schema" in result and "nope" not in result and result.get("nope", 1) == 1
    with pytest.raises(KeyError):
        result["nope"]
    records = result.to_records()
    assert [r["method"] for r in records] == ["q-learning", "bayes-rl", "scaled"]
    assert {"success_rate", "success_rate_ci95_low", "success_rate_min", "worst_seed_train_seed"} <= set(records[0])
    assert records[2]["success_rate"] == data["tables"][0]["methods"][2]["success_rate"]["mean"]


def test_to_pandas_gives_the_records_or_names_the_extra(agent, monkeypatch):
    result = unforeseen.evaluate_builtin("jaywalk", "never-brake", episodes=3)
    try:
        import pandas
    except ImportError:
        pandas = None
    if pandas is not None:
        frame = result.to_pandas()
        assert len(frame) == 3 and list(frame["success"]) == [e["success"] for e in result.episodes]
    monkeypatch.setitem(sys.modules, "pandas", None)
    with pytest.raises(ImportError, match=r"unforeseen\[pandas\]"):
        result.to_pandas()


def test_a_python_policys_lines_print_as_the_batch_of_the_same_agent(agent, tmp_path):
    # The scaled agent around its own Q-table habit, evaluated from Python, gives the
    # built-in scaled agent's lines (test_wrapper.py), so the same summary table.
    out = tmp_path / "results.jsonl"
    lines = unforeseen.evaluate(unforeseen.ScaledWrapper(agent=agent, method="scaled"), ["jaywalk"], [7],
                                episodes=4, seed=7, out=out)
    assert isinstance(lines, unforeseen.EvaluateResult) and isinstance(lines, list) and len(lines) == 2
    built_in = unforeseen.batch("jaywalk", agent=agent, episodes=4, seed=7, methods=["scaled"],
                                out=tmp_path / "built_in.jsonl")
    assert str(lines) == str(built_in)
    assert lines.report.summary == unforeseen.summarize(out)
    assert "| jaywalk | scaled | default | zero-shot | 1 |" in lines._repr_markdown_()
    assert lines._repr_html_().count("<table>") == 1


def test_the_ray_drivers_join_prints_the_batchs_table_and_failures(agent_file, tmp_path):
    # finish_batch joins the file a Ray driver wrote; here the command line's own file,
    # on a map whose expectations this small agent fails.
    out = tmp_path / "b.jsonl"
    binary = required_cli()
    maps = [str(REPO / "maps" / "red_light" / "two_pedestrians.ron"), str(REPO / "maps" / "jaywalk.ron")]
    run = subprocess.run([str(binary), "batch", *maps, "--agent", str(agent_file), "--episodes", "2",
                          "--method", "scaled", "--method", "never-brake", "--quiet", "--out", str(out)],
                         capture_output=True, text=True)
    printed = "\n".join(run.stdout.rstrip("\n").split("\n")[:-1])
    failed = [l.removeprefix("expectation failed: ") for l in run.stderr.splitlines()
              if l.startswith("expectation failed: ")]
    assert failed, "the small agent should fail an expectation here"
    joined = _unforeseen.finish_batch(str(out))
    assert str(joined) == printed
    assert joined.failures == joined["failures"] == failed

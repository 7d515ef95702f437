"""Three fronts, one core: the same batch or search request through the command line, the
Ray driver and the library gives the same results, line for line (the wall-clock figures
aside). The batch request has an agent file, scripted and learning methods, both
protocols and a sweep, so that agent choice, run identity, protocols and parameter sets
all cross each front; the search runs every stage (Sobol, adaptive, minimisation)."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

import unforeseen
from conftest import REPO
from test_agents import required_cli
from test_distributed import _InlineRay, _search_outputs

MAPS = [str(REPO / "maps" / "jaywalk.ron"), str(REPO / "maps" / "stop_midway.ron")]
METHODS = ["scaled", "q-learning", "brake-on-pedestrian"]


def _cli(*args: str) -> None:
    cli = required_cli()
    subprocess.run([str(cli), *args], check=True, capture_output=True, timeout=300)


def _untimed(lines: list[dict]) -> list[dict]:
    for line in lines:
        line.pop("timing_us_per_tick", None)
    return lines


def _file_lines(path: Path) -> list[dict]:
    return _untimed([json.loads(line) for line in path.read_text().splitlines()])


def test_one_batch_request_gives_the_same_lines_through_every_front(agent_file: Path, tmp_path: Path,
                                                                    monkeypatch: pytest.MonkeyPatch):
    cli_out = tmp_path / "cli.jsonl"
    method_args = [a for m in METHODS for a in ("--method", m)]
    _cli("batch", *MAPS, "--agent", str(agent_file), *method_args, "--protocol", "both", "--set", "horizon=2,3",
         "--episodes", "3", "--seed", "5", "-q", "--out", str(cli_out))
    expected = _file_lines(cli_out)

    monkeypatch.setitem(sys.modules, "ray", _InlineRay())
    from unforeseen.distributed import run_batch

    ray_out = tmp_path / "ray.jsonl"
    run_batch(MAPS, out=ray_out, agent=agent_file, methods=METHODS, protocol="both", sets=["horizon=2,3"],
              episodes=3, seed=5, quiet=True)
    assert _file_lines(ray_out) == expected

    library = unforeseen.batch(*MAPS, agents=unforeseen.load_agent(str(agent_file)), methods=METHODS,
                               protocols=["zero-shot", "continual"], sweep={"horizon": [2, 3]}, episodes=3, seed=5)
    # The library's lines are the results file's after its `run` line.
    assert _untimed(list(library["lines"])) == expected[1:]


def test_one_search_request_gives_the_same_outputs_through_every_front(agent_file: Path, tmp_path: Path,
                                                                       monkeypatch: pytest.MonkeyPatch):
    space = REPO / "maps" / "spaces" / "jaywalk.ron"
    args = dict(budget=6, episodes=3, seed=5, rounds=2, max_failures=1)
    cli_out = tmp_path / "cli"
    _cli("search", "--space", str(space), "--method", "q-learning", "--agent", str(agent_file), "--budget", "6",
         "--episodes", "3", "--seed", "5", "--rounds", "2", "--max-failures", "1", "--jobs", "1", "--quiet",
         "--out", str(cli_out))
    expected = _search_outputs(cli_out)
    counts = expected["summary"]["counts"]
    assert counts["sobol"] == 3 and counts["adaptive"] == 3 and counts["minimise"] > 0, counts

    library_out = tmp_path / "library"
    unforeseen.search(space=space, method="q-learning", agent=agent_file, out=library_out, **args)
    assert _search_outputs(library_out) == expected

    monkeypatch.setitem(sys.modules, "ray", _InlineRay())
    from unforeseen.distributed import run_search

    ray_out = tmp_path / "ray"
    run_search(space=space, method="q-learning", agent=agent_file, out=ray_out, **args)
    assert _search_outputs(ray_out) == expected

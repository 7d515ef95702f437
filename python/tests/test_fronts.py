"""Three fronts, one core: the same batch or search request through the command line, the
Ray driver and the library gives the same results file, byte for byte (the wall-clock
figures aside); the library and the Ray driver take the request's fields with the
library's defaults; a bad field is named as the field in Python and as its flag on the
command line. The batch request has an agent file, scripted and learning methods, both
protocols and a sweep, so that agent choice, run identity, protocols and parameter sets
all cross each front; the search runs every stage (Sobol, adaptive, minimisation)."""

from __future__ import annotations

import inspect
import json
import re
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

import unforeseen
from conftest import REPO
from test_agents import required_cli
from test_distributed import _InlineRay, _search_outputs

MAPS = [str(REPO / "maps" / "jaywalk.ron"), str(REPO / "maps" / "stop_midway.ron")]
METHODS = ["scaled", "q-learning", "brake-on-pedestrian"]


def _cli(*args: str) -> str:
    cli = required_cli()
    return subprocess.run([str(cli), *args], check=True, capture_output=True, text=True, timeout=300).stdout


def _file_lines(path: Path) -> list[dict]:
    return _untimed([json.loads(line) for line in path.read_text().splitlines()])


def _untimed_text(path: Path) -> str:
    """A results file's bytes with the wall-clock figures' values taken out."""
    return re.sub(r'"timing_us_per_tick":[^,}]+', '"timing_us_per_tick":_', path.read_text())


def test_one_batch_request_gives_the_same_file_through_every_front(agent_file: Path, tmp_path: Path,
                                                                   monkeypatch: pytest.MonkeyPatch):
    cli_out = tmp_path / "cli.jsonl"
    method_args = [a for m in METHODS for a in ("--method", m)]
    _cli("batch", *MAPS, "--agent", str(agent_file), *method_args, "--protocol", "both", "--set", "horizon=2,3",
         "--episodes", "3", "--seed", "5", "-q", "--out", str(cli_out))
    expected = _untimed_text(cli_out)
    assert '"param_set":"horizon=3"' in expected and '"protocol":"continual"' in expected

    # The same request, in the same words, through the library and through Ray.
    request = dict(agent=agent_file, methods=METHODS, protocol="both", sets=["horizon=2,3"], episodes=3, seed=5)
    library_out = tmp_path / "library.jsonl"
    library = unforeseen.batch(MAPS, out=library_out, **request)
    assert _untimed_text(library_out) == expected
    # The library's lines are the results file's after its `run` line.
    assert _untimed(list(library["lines"])) == _file_lines(cli_out)[1:]
    # An agent given loaded is the agent of its file: the same run, the same bytes.
    loaded_out = tmp_path / "loaded.jsonl"
    unforeseen.batch(MAPS, out=loaded_out, **{**request, "agent": unforeseen.load_agent(str(agent_file))})
    assert _untimed_text(loaded_out) == expected

    monkeypatch.setitem(sys.modules, "ray", _InlineRay())
    from unforeseen.distributed import run_batch

    ray_out = tmp_path / "ray.jsonl"
    on_ray = run_batch(MAPS, out=ray_out, quiet=True, **request)
    assert _untimed_text(ray_out) == expected
    # The same report from both: one batch API.
    assert type(on_ray) is type(library)
    assert _untimed(list(on_ray.lines)) == _untimed(list(library.lines))
    assert on_ray.failures == library.failures and on_ray.checked == library.checked


def test_the_ray_drivers_command_prints_what_batch_prints(agent_file: Path, tmp_path: Path,
                                                          monkeypatch: pytest.MonkeyPatch, capsys):
    monkeypatch.setitem(sys.modules, "ray", _InlineRay())
    from unforeseen import distributed

    args = [*MAPS, "--agent", str(agent_file), "--method", "never-brake", "--episodes", "2", "--seed", "5"]
    cli = _cli("batch", *args, "-q", "--out", str(tmp_path / "cli.jsonl"))
    code = distributed.main(["batch", *args, "--quiet", "--out", str(tmp_path / "ray.jsonl")])
    printed = capsys.readouterr().out
    assert code == 0
    # The table, then the line saying what was written (its paths differ).
    assert printed.split("\nwrote ")[0] == cli.split("\nwrote ")[0]
    assert "expectation(s) checked on the mean over training seeds, 0 failed" in printed


def _request_parameters(function: Any, ray_only: set[str]) -> dict[str, Any]:
    return {name: p.default for name, p in inspect.signature(function).parameters.items() if name not in ray_only}


def _as_json(value: Any) -> Any:
    return list(value) if isinstance(value, tuple) else value


@pytest.mark.parametrize("job", ["batch", "search", "estimate"])
def test_local_and_ray_take_the_request_with_the_librarys_defaults(job: str):
    from unforeseen import distributed
    from unforeseen.requests import BATCH_DEFAULTS, ESTIMATE_DEFAULTS, PYTHON_DEFAULTS, SEARCH_DEFAULTS, flag

    local, ray, defaults, ray_only = {
        "batch": (unforeseen.batch, distributed.run_batch, BATCH_DEFAULTS,
                  {"units_per_task", "address", "max_retries", "quiet"}),
        "search": (unforeseen.search, distributed.run_search, SEARCH_DEFAULTS,
                   {"candidates_per_task", "address", "max_retries", "command"}),
        "estimate": (unforeseen.estimate, distributed.run_estimate, ESTIMATE_DEFAULTS,
                     {"candidates_per_task", "address", "max_retries"}),
    }[job]
    on_ray = _request_parameters(ray, ray_only)
    assert on_ray == _request_parameters(local, {"command"}), "the same arguments, names and defaults"
    given = {k: _as_json(v) for k, v in on_ray.items()}
    # The space has no default: the request refuses it empty, Python takes None for it.
    # Python takes the library's defaults but for PYTHON_DEFAULTS (no agent cache unless given).
    assert given == {**defaults, **PYTHON_DEFAULTS, **({"space": None} if job != "batch" else {})}
    # The Ray driver's command has one option per field, spelt as the command line's flag.
    parser = distributed._parser()
    actions = parser._subparsers._group_actions[0].choices[job]._actions
    given_nothing = vars(parser.parse_args([job]))
    for field, default in defaults.items():
        spellings = [s for a in actions if a.dest == field for s in a.option_strings]
        assert flag(field) in spellings or (field == "maps" and spellings == []), (field, spellings)
        # With nothing given, the command's request is the library's default.
        assert given_nothing[field] == default, field


@pytest.mark.parametrize("job", ["compare", "eval"])
def test_compare_and_eval_take_the_request_with_the_librarys_defaults(job: str):
    from unforeseen.requests import COMPARE_DEFAULTS, EVAL_DEFAULTS, PYTHON_DEFAULTS

    function, defaults, given_loaded = {
        "compare": (unforeseen.compare, COMPARE_DEFAULTS, {"agents"}),
        "eval": (unforeseen.evaluate_builtin, EVAL_DEFAULTS, set()),
    }[job]
    taken = {k: _as_json(v) for k, v in _request_parameters(function, given_loaded).items()}
    own = {k: v for k, v in PYTHON_DEFAULTS.items() if k in defaults}
    assert taken == {**defaults, **own}, "the request's fields, names and defaults"


@pytest.mark.parametrize(
    "function,field,request_field",
    [
        ("train", "map", ("compare", "train_map")),
        ("train", "episodes", ("compare", "train_episodes")),
        ("train", "seed", ("compare", "seed")),
        ("train_agents", "map", ("compare", "train_map")),
        ("train_agents", "episodes", ("compare", "train_episodes")),
        ("train_agents", "timeout_as", ("compare", "timeout_as")),
        ("rollout", "map", ("eval", "map")),
        ("rollout", "method", ("eval", "method")),
        ("rollout", "episodes", ("eval", "episodes")),
        ("rollout", "protocol", ("eval", "protocol")),
        ("rollout", "seed", ("eval", "seed")),
        ("evaluate", "episodes", ("eval", "episodes")),
        ("evaluate", "seed", ("eval", "seed")),
        ("evaluate_policy", "episodes", ("eval", "episodes")),
        ("evaluate_policy", "protocol", ("eval", "protocol")),
        ("evaluate_policy", "seed", ("eval", "seed")),
    ],
)
def test_the_other_functions_take_the_requests_defaults(function: str, field: str, request_field: tuple[str, str]):
    """A default the functions outside the requests spell (training episodes, the seed,
    the maps) is the library's: a default changed by hand in one place fails here."""
    from unforeseen.requests import COMPARE_DEFAULTS, EVAL_DEFAULTS

    job, name = request_field
    expected = {"compare": COMPARE_DEFAULTS, "eval": EVAL_DEFAULTS}[job][name]
    assert inspect.signature(getattr(unforeseen, function)).parameters[field].default == expected


def test_the_same_compare_and_eval_through_python_and_the_command_line_write_the_same_files(agent_file, tmp_path):
    cli = required_cli()
    common = ["--agent", str(agent_file), "--episodes", "2", "--seed", "5", "--set", "horizon=2", "--quiet"]
    subprocess.run([str(cli), "compare", *common, "--protocol", "zero-shot", "--out", str(tmp_path / "c-cli")],
                   check=True, capture_output=True, timeout=300)
    unforeseen.compare(agent=agent_file, episodes=2, seed=5, sets=["horizon=2"], protocol="zero-shot",
                       out=tmp_path / "c-py")
    subprocess.run([str(cli), "eval", *common, "--map", "two_pedestrians", "--protocol", "continual",
                    "--out", str(tmp_path / "e-cli")], check=True, capture_output=True, timeout=300)
    unforeseen.evaluate_builtin("two_pedestrians", agent=agent_file, episodes=2, seed=5, sets=["horizon=2"],
                                protocol="continual", out=tmp_path / "e-py")
    for folder, name in [("c", "compare.json"), ("e", "eval.json")]:
        on_cli, on_py = (_untimed(json.loads((tmp_path / f"{folder}-{front}" / name).read_text()))
                         for front in ("cli", "py"))
        assert on_cli == on_py, name
    seeds = [(tmp_path / f"c-{front}" / "compare_seeds.csv").read_text().splitlines() for front in ("cli", "py")]
    assert seeds[0][0] == seeds[1][0] and len(seeds[0]) == len(seeds[1]) > 1


def _untimed(value: Any) -> Any:
    """A report's data without the wall-clock figures (every key that measures µs or ns)."""
    if isinstance(value, dict):
        timed = ("us_per", "_ns")
        return {k: _untimed(v) for k, v in value.items() if not any(t in k for t in timed)}
    if isinstance(value, list):
        return [_untimed(v) for v in value]
    return value


def test_a_bad_field_names_the_field_in_python_and_the_flag_on_the_command_line(tmp_path: Path):
    with pytest.raises(ValueError, match="^train_seeds: '3..1': the range runs backwards"):
        unforeseen.batch("jaywalk", train_seeds="3..1", out=tmp_path / "r.jsonl")
    with pytest.raises(ValueError, match="^sets horizon=1,,2: an empty value"):
        unforeseen.batch("jaywalk", sets=["horizon=1,,2"], methods=["never-brake"], out=tmp_path / "r.jsonl")
    with pytest.raises(ValueError, match=r"^budget 0: expected a whole number in 1\.\.=1000000"):
        unforeseen.search(REPO / "maps" / "spaces" / "jaywalk.ron", budget=0, method="never-brake",
                          out=tmp_path / "s")
    cli = required_cli()
    for args, said in [(["--train-seeds", "3..1"], "--train-seeds"),
                       (["--set", "horizon=1,,2", "--method", "never-brake"], "error: --set horizon=1,,2: an empty value")]:
        run = subprocess.run([str(cli), "batch", "jaywalk", *args, "--out", str(tmp_path / "r.jsonl")],
                             capture_output=True, text=True, timeout=120)
        assert run.returncode == 2 and said in run.stderr, run.stderr
    run = subprocess.run([str(cli), "search", "--space", str(REPO / "maps" / "spaces" / "jaywalk.ron"), "--budget",
                          "0", "--method", "never-brake", "--out", str(tmp_path / "s")],
                         capture_output=True, text=True, timeout=120)
    assert run.returncode == 2 and "error: --budget 0: expected 1 to" in run.stderr, run.stderr
    assert not (tmp_path / "r.jsonl").exists()


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


def test_one_estimate_request_gives_the_same_files_through_every_front(agent_file: Path, tmp_path: Path,
                                                                       monkeypatch: pytest.MonkeyPatch):
    """The command line, the library and the Ray driver write the same estimate.jsonl and
    summary.json, byte for byte, for every estimator (importance sampling's rounds refit
    the proposal from the draws, so a draw evaluated otherwise would change every later one)."""
    space = REPO / "maps" / "spaces" / "jaywalk.ron"
    monkeypatch.setitem(sys.modules, "ray", _InlineRay())
    from unforeseen.distributed import run_estimate

    for estimator, budget in [("mc", 50), ("is", 200), ("is-fails", 200)]:
        # A target no run reaches, so every stage runs (Q-learning fails nearly every fair
        # draw: `is` would reach the default ±30% on P(fails | fair) in its first block).
        args = dict(space=str(space), method="q-learning", agent=str(agent_file), estimator=estimator, budget=budget,
                    episodes=1, seed=5, target_rel_error=0.01)
        cli_out = tmp_path / f"{estimator}-cli"
        _cli("estimate", "--space", str(space), "--method", "q-learning", "--agent", str(agent_file), "--estimator",
             estimator, "--budget", str(budget), "--episodes", "1", "--seed", "5", "--target-rel-error", "0.01",
             "--jobs", "1", "--quiet", "--out", str(cli_out))
        files = ["estimate.jsonl", "summary.json"]
        expected = [(cli_out / f).read_bytes() for f in files]
        assert json.loads(expected[1])["evaluations"] == budget
        unforeseen.estimate(**args, out=tmp_path / f"{estimator}-py")
        run_estimate(**args, out=tmp_path / f"{estimator}-ray", candidates_per_task=7)
        for front in ("py", "ray"):
            assert [(tmp_path / f"{estimator}-{front}" / f).read_bytes() for f in files] == expected, (estimator, front)


def test_an_interrupted_estimate_resumes_to_the_command_lines_files_through_every_front(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch):
    """An estimate killed partway (its draws' part cut mid-line, no estimate.jsonl) resumed
    by the library (``resume=True``) and by the Ray driver writes the command line's
    uninterrupted files, byte for byte, for every estimator (for `is` and `is-fails` the
    rounds' refits redone from the kept draws); shards run from Python,
    concatenated and resumed, too. The Ray driver refuses a shard, and a bad one is named."""
    space = str(REPO / "maps" / "spaces" / "jaywalk.ron")
    monkeypatch.setitem(sys.modules, "ray", _InlineRay())
    from unforeseen.distributed import run_estimate

    files = ["estimate.jsonl", "summary.json"]
    for estimator, budget in [("mc", 100), ("is", 200), ("is-fails", 200)]:
        args = dict(space=space, method="never-brake", estimator=estimator, budget=budget, episodes=1, seed=5,
                    target_rel_error=0.05)
        cli_out = tmp_path / f"{estimator}-cli"
        _cli("estimate", "--space", space, "--method", "never-brake", "--estimator", estimator, "--budget",
             str(budget), "--episodes", "1", "--seed", "5", "--target-rel-error", "0.05", "--jobs", "1", "--quiet",
             "--out", str(cli_out))
        expected = [(cli_out / f).read_bytes() for f in files]
        cut = expected[0][: len(expected[0]) * 3 // 5]
        for front, run in [("py", unforeseen.estimate), ("ray", run_estimate)]:
            out = tmp_path / f"{estimator}-{front}"
            out.mkdir()
            (out / "estimate.jsonl.part").write_bytes(cut)
            summary = run(**args, out=out, resume=True)
            assert summary["evaluations"] == json.loads(expected[1])["evaluations"]
            assert [(out / f).read_bytes() for f in files] == expected, (estimator, front)
            assert not (out / "estimate.jsonl.part").exists()

    mc = dict(space=space, method="never-brake", budget=100, episodes=1, seed=5, target_rel_error=0.05)
    joined = b""
    for shard in ("1/2", "2/2"):
        part = unforeseen.estimate(**mc, shard=shard, out=tmp_path / f"shard{shard[0]}")
        assert (part["shard"], part["stage"], part["share"], part["evaluated"]) == (shard, "uniform", 50, 50)
        joined += (tmp_path / f"shard{shard[0]}" / "estimate.jsonl").read_bytes()
    (tmp_path / "joined").mkdir()
    (tmp_path / "joined" / "estimate.jsonl").write_bytes(joined)
    unforeseen.estimate(**mc, resume=True, out=tmp_path / "joined")
    assert [(tmp_path / "joined" / f).read_bytes() for f in files] == [
        (tmp_path / "mc-cli" / f).read_bytes() for f in files]

    with pytest.raises(ValueError, match=r"shard 1/2: the cluster splits the run itself"):
        run_estimate(**mc, shard="1/2", out=tmp_path / "ray-shard")
    with pytest.raises(ValueError, match=r"^shard"):
        unforeseen.estimate(**mc, shard="3/2", out=tmp_path / "bad-shard")


def test_a_training_map_crosses_every_front(tmp_path: Path, monkeypatch: pytest.MonkeyPatch):
    """A search and an estimate whose agents train on a map file other than the default
    (``train_map``, ``--train-map``): the command line, the library and the Ray driver
    (whose agents train on the cluster) write the same outputs, and the agents' identity
    names the training map."""
    train_map = tmp_path / "short.ron"
    train_map.write_text('Map(base: "intersection", name: "short_intersection", episode: (max_steps: 60))')
    space = REPO / "maps" / "spaces" / "jaywalk.ron"
    agents = ["--method", "q-learning", "--train-seeds", "1", "--train-episodes", "20", "--train-map", str(train_map),
              "--no-cache", "--episodes", "1", "--seed", "5", "--jobs", "1", "--quiet"]
    args = dict(space=space, method="q-learning", train_seeds=[1], train_episodes=20, train_map=train_map, episodes=1,
                seed=5)
    monkeypatch.setitem(sys.modules, "ray", _InlineRay())
    from unforeseen.distributed import run_estimate, run_search

    _cli("search", "--space", str(space), *agents, "--budget", "4", "--rounds", "1", "--max-failures", "0",
         "--out", str(tmp_path / "s-cli"))
    expected = _search_outputs(tmp_path / "s-cli")
    assert expected["candidates"][0]["search"]["agents"].startswith("trained on short_intersection for 20 episodes")
    search_args = dict(budget=4, rounds=1, max_failures=0)
    unforeseen.search(out=tmp_path / "s-py", **args, **search_args)
    run_search(out=tmp_path / "s-ray", **args, **search_args)
    for front in ("py", "ray"):
        assert _search_outputs(tmp_path / f"s-{front}") == expected, front

    _cli("estimate", "--space", str(space), *agents, "--budget", "50", "--out", str(tmp_path / "e-cli"))
    files = ["estimate.jsonl", "summary.json"]
    expected_files = [(tmp_path / "e-cli" / f).read_bytes() for f in files]
    assert b"trained on short_intersection for 20 episodes" in expected_files[0]
    unforeseen.estimate(out=tmp_path / "e-py", budget=50, **args)
    run_estimate(out=tmp_path / "e-ray", budget=50, candidates_per_task=7, **args)
    for front in ("py", "ray"):
        assert [(tmp_path / f"e-{front}" / f).read_bytes() for f in files] == expected_files, front

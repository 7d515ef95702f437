"""Every writer of the Python front keeps the README's promise ("Bad input"; issue 49,
the command line's side in tests/it/writers.rs): a file at an output that is not of the
writer's own kind (recognised by its content) raises ``ValueError`` naming the file and
what it holds, and is left byte for byte, unless ``force=True``; a refusal changes
nothing (``batch(resume=True)``, the Ray driver without Ray, ``evaluate(force=True)``
refused later); ``train_agents`` checks its cache before any training."""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

import unforeseen
from conftest import REPO
from test_agents import required_cli

MAPS = REPO / "maps"
TINY = ('Map(base: "intersection", name: "tiny", bins: (distance_edges: [0.0, 45.0], speed_edges: [4.5]), '
        "episode: (max_steps: 12))")


class AlwaysFast:
    method = "always-fast"

    def act(self, obs):
        return 1


#: What the refusal says each kind of file holds.
HELD = {
    "map": "holds a map",
    "space": "holds a search space",
    "agent": "holds an agent file",
    "results": "holds a batch's results",
    "summary": "holds a batch's summary",
    "candidates": "holds a search's candidates",
    "estimates": "holds an estimate's draws",
    "estimate-summary": "holds an estimate's summary",
    "model": "holds a planning model",
    "stream": "holds a deployment stream",
    "html": "holds an HTML page",
    "svg": "holds an SVG figure",
}


@pytest.fixture(scope="module")
def foreign(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """One real file of every kind, each written by the command that writes it."""
    d = tmp_path_factory.mktemp("foreign")
    (d / "tiny.ron").write_text(TINY)
    agent = unforeseen.train(str(d / "tiny.ron"), episodes=20, seed=3)
    agent.save(d / "agent.ron")
    unforeseen.batch(str(d / "tiny.ron"), methods=["never-brake"], episodes=1, out=d / "results.jsonl", cache=None)
    cli = required_cli()
    run = lambda *a: subprocess.run([str(cli), *a], check=True, capture_output=True, timeout=300)  # noqa: E731
    run("search", "--method", "never-brake", "--budget", "2", "--episodes", "1", "--jobs", "1", "--space",
        str(MAPS / "spaces" / "jaywalk.ron"), "--out", str(d / "search"))
    run("estimate", "--method", "never-brake", "--budget", "50", "--episodes", "1", "--jobs", "1", "-q", "--space",
        str(MAPS / "spaces" / "jaywalk.ron"), "--out", str(d / "estimate"))
    run("export-model", "--agent", str(d / "agent.ron"), "--obs", "1,1,1,1", "--out", str(d / "model.json"))
    run("trace", "--map", str(d / "tiny.ron"), "--agent", str(d / "agent.ron"), "-q", "--out", str(d / "trace"),
        "--html", str(d / "page.html"))
    files = {
        "map": MAPS / "jaywalk.ron",
        "space": MAPS / "spaces" / "jaywalk.ron",
        "agent": d / "agent.ron",
        "results": d / "results.jsonl",
        "summary": d / "results.summary.json",
        "candidates": d / "search" / "candidates.jsonl",
        "estimates": d / "estimate" / "estimate.jsonl",
        "estimate-summary": d / "estimate" / "summary.json",
        "model": d / "model.json",
        "stream": MAPS / "streams" / "deployment.ron",
        "html": d / "page.html",
        "svg": d / "trace" / "theta.svg",
    }
    for kind, p in files.items():
        assert p.is_file(), (kind, p)
    files["_tiny"] = d / "tiny.ron"
    files["_agent"] = d / "agent.ron"
    return files


def _save(f, out, force):
    agent = unforeseen.load_agent(f["_agent"])
    return agent.save(out, force=True) if force else agent.save(out)


def _evaluate(f, out, force):
    return unforeseen.evaluate(AlwaysFast(), [str(f["_tiny"])], [None], episodes=1, protocol="zero-shot", out=out,
                               force=force)


def _batch(f, out, force):
    return unforeseen.batch(str(f["_tiny"]), methods=["never-brake"], episodes=1, out=out, force=force, cache=None)


def _eval_builtin(f, out, force):
    return unforeseen.evaluate_builtin(str(f["_tiny"]), "never-brake", episodes=1, out=out, agent=f["_agent"],
                                       force=force)


def _compare(f, out, force):
    return unforeseen.compare(agent=f["_agent"], train_map=str(f["_tiny"]), test_map=str(f["_tiny"]), episodes=1,
                              protocol="zero-shot", out=out, force=force, cache=None)


def _search(f, out, force):
    from unforeseen.search import search

    return search(MAPS / "spaces" / "jaywalk.ron", method="never-brake", budget=2, episodes=1, jobs=1, out=out,
                  force=force, cache=None)


def _estimate(f, out, force):
    return unforeseen.estimate(MAPS / "spaces" / "jaywalk.ron", method="never-brake", budget=50, episodes=1, jobs=1,
                               out=out, force=force, cache=None)


#: (writer, call, outputs: (name inside a folder out, or "" for the file out itself, or
#: ".summary.json" beside it; the kind written there, None for one not in HELD)).
WRITERS = [
    ("Agent.save", _save, False, [("", "agent")]),
    # evaluate appends result lines (its own kind); a batch run's file is refused too (below).
    ("evaluate", _evaluate, False, [("", "results")]),
    ("batch", _batch, False, [("", "results"), (".summary.json", "summary")]),
    ("evaluate_builtin", _eval_builtin, True, [("eval.json", None)]),
    ("compare", _compare, True, [("compare.json", None), ("compare.csv", None), ("compare_seeds.csv", None),
                                 ("compare.svg", "svg")]),
    ("search", _search, True, [("candidates.jsonl", "candidates"), ("candidates.jsonl.part", "candidates"),
                               ("summary.json", None), ("search.svg", "svg")]),
    ("estimate", _estimate, True, [("estimate.jsonl", "estimates"), ("estimate.jsonl.part", "estimates"),
                                   ("summary.json", "estimate-summary")]),
]

CASES = [(w, call, folder, name, kind) for (w, call, folder, outs) in WRITERS for (name, own) in outs
         for kind in HELD if kind != own]


def _place(tmp_path: Path, folder: bool, name: str) -> tuple[Path, Path]:
    if folder:
        return tmp_path / "o", tmp_path / "o" / name
    out = tmp_path / "r.jsonl"
    return out, (out if not name else tmp_path / "r.summary.json")


@pytest.mark.parametrize("writer,call,folder,name,kind", CASES, ids=[f"{c[0]}-{c[3] or 'out'}-{c[4]}" for c in CASES])
def test_no_writer_replaces_a_file_of_another_kind(foreign, tmp_path, writer, call, folder, name, kind):
    out, target = _place(tmp_path, folder, name)
    target.parent.mkdir(parents=True, exist_ok=True)
    shutil.copyfile(foreign[kind], target)
    before = target.read_bytes()
    with pytest.raises(ValueError) as e:
        call(foreign, out, False)
    assert target.name in str(e.value) and HELD[kind] in str(e.value), str(e.value)
    assert target.read_bytes() == before


@pytest.mark.parametrize("writer,call,folder,outs", WRITERS, ids=[w[0] for w in WRITERS])
def test_force_replaces_a_foreign_file(foreign, tmp_path, writer, call, folder, outs):
    out, target = _place(tmp_path, folder, outs[0][0])
    target.parent.mkdir(parents=True, exist_ok=True)
    shutil.copyfile(foreign["map"], target)
    call(foreign, out, True)
    assert target.read_bytes() != foreign["map"].read_bytes()
    call(foreign, out, False) if writer not in ("evaluate",) else None  # its own file from an earlier run


def _snapshot(d: Path) -> dict[str, bytes]:
    return {str(p): p.read_bytes() for p in sorted(d.rglob("*")) if p.is_file() and not p.name.endswith("lock")}


def test_a_refused_batch_resume_keeps_the_earlier_summary(tmp_path):
    out = tmp_path / "r.jsonl"
    unforeseen.batch("jaywalk", methods=["never-brake"], episodes=2, out=out, cache=None)
    assert (tmp_path / "r.summary.json").is_file()
    before = _snapshot(tmp_path)
    with pytest.raises(ValueError, match="episodes"):
        unforeseen.batch("jaywalk", methods=["never-brake"], episodes=3, out=out, resume=True, cache=None)
    assert _snapshot(tmp_path) == before


def test_the_ray_driver_without_ray_keeps_the_earlier_summary(tmp_path, monkeypatch):
    from unforeseen import distributed

    out = tmp_path / "r.jsonl"
    unforeseen.batch("jaywalk", methods=["never-brake"], episodes=1, out=out, cache=None)
    before = _snapshot(tmp_path)
    monkeypatch.setitem(sys.modules, "ray", None)  # `import ray` raises ImportError
    with pytest.raises(ImportError, match="Ray"):
        distributed.run_batch("jaywalk", methods=["never-brake"], episodes=1, out=out)
    assert _snapshot(tmp_path) == before


def test_evaluate_with_force_refused_later_keeps_the_file(tmp_path):
    out = tmp_path / "r.jsonl"
    unforeseen.batch("jaywalk", methods=["never-brake", "brake-on-pedestrian"], episodes=1, out=out, cache=None)
    before = _snapshot(tmp_path)
    # A batch run's file (its first line names the run) is not evaluate's own kind.
    with pytest.raises(ValueError, match="force"):
        unforeseen.evaluate(AlwaysFast(), ["jaywalk"], [None], episodes=1, protocol="zero-shot", out=out)
    assert _snapshot(tmp_path) == before
    # With force=True, a refusal after the guard (a map that does not load) keeps it too.
    with pytest.raises(ValueError):
        unforeseen.evaluate(AlwaysFast(), [str(tmp_path / "missing.ron")], [None], episodes=1, protocol="zero-shot",
                            out=out, force=True)
    assert _snapshot(tmp_path) == before


def test_train_agents_checks_its_cache_before_any_training(tmp_path):
    cache = tmp_path / "jw.ron"
    cache.write_bytes((MAPS / "jaywalk.ron").read_bytes())
    with pytest.raises(ValueError, match="cache"):
        unforeseen.train_agents([1, 2], episodes=2000, cache=cache)
    assert cache.read_bytes() == (MAPS / "jaywalk.ron").read_bytes()


def test_a_results_header_names_what_evaluate_wrote(tmp_path):
    # evaluate's own file: result lines (no run header); a second method goes beside them
    # when asked (append=True).
    out = tmp_path / "r.jsonl"
    unforeseen.evaluate(AlwaysFast(), ["jaywalk"], [None], episodes=1, protocol="zero-shot", out=out)
    unforeseen.evaluate(AlwaysFast(), ["jaywalk"], [None], episodes=1, protocol="zero-shot", out=out, method="b",
                        append=True)
    assert [json.loads(line)["method"] for line in out.read_text().splitlines()] == ["always-fast", "b"]

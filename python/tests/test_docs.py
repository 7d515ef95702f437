"""Commands the docs give run as written: python/bench.py as its docstring says, and every
`python -m unforeseen.baselines` command of the baselines module's docstring and of the
README parses with the module's own argument parser."""

from __future__ import annotations

import json
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

import unforeseen
from unforeseen import baselines

REPO = Path(__file__).resolve().parents[2]


def test_bench_runs_as_its_docstring_says():
    doc = (REPO / "python" / "bench.py").read_text()
    assert "python python/bench.py " in doc
    # From the repository's root, as written (small sizes): python/ must not shadow the
    # installed package.
    out = subprocess.run(
        [sys.executable, "python/bench.py", "--steps", "100", "--repeats", "1"],
        cwd=REPO, capture_output=True, text=True, timeout=300,
    )
    assert out.returncode == 0, out.stderr
    result = json.loads(out.stdout)
    # The installed package, the one these tests import (a stale extension beside the
    # sources in python/unforeseen must not be what the bench measures).
    assert Path(result["package"]).resolve() == Path(unforeseen.__file__).resolve()
    figures = result["unforeseen"]
    assert [f["decision_hz"] for f in figures] == [1, 10]
    assert all(f["vector_64_steps_per_s"] > 0 for f in figures)


def _baselines_commands(text: str) -> list[list[str]]:
    """Every `python -m unforeseen.baselines ...` command of `text`, continuation lines joined."""
    joined = re.sub(r"\\\n\s*", " ", text)
    return [shlex.split(m)[3:] for m in re.findall(r"python -m unforeseen\.baselines [^\n`]*", joined)]


@pytest.mark.parametrize("source", ["docstring", "README"])
def test_baselines_commands_in_the_docs_parse(source):
    text = baselines.__doc__ if source == "docstring" else (REPO / "README.md").read_text()
    commands = _baselines_commands(text)
    assert {c[0] for c in commands} == {"train", "evaluate"}, commands
    for argv in commands:
        try:
            baselines.parser().parse_args(argv)
        except SystemExit:
            pytest.fail(f"{source}: `python -m unforeseen.baselines {shlex.join(argv)}` does not parse")

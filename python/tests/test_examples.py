"""Every Python example of examples/ runs to the end at small sizes
(UNFORESEEN_EXAMPLE_SMALL=1), in a scratch folder. examples/pymdp_tmaze.py needs pymdp
(the ``pymdp`` extra): it is skipped without it, except in CI, which sets
UNFORESEEN_REQUIRE_PYMDP=1."""

from __future__ import annotations

import importlib.util
import os
import subprocess
import sys
from pathlib import Path

import pytest

EXAMPLES = sorted((Path(__file__).resolve().parents[2] / "examples").glob("*.py"))


#: Examples that need an optional module, and the module.
NEEDS = {"pymdp_tmaze.py": "pymdp"}


def test_there_are_examples():
    names = {p.name for p in EXAMPLES}
    assert {"python_tour.py", "pymdp_tmaze.py"} <= names


@pytest.mark.parametrize("example", EXAMPLES, ids=[p.name for p in EXAMPLES])
def test_example_runs(example, tmp_path):
    module = NEEDS.get(example.name)
    if module and importlib.util.find_spec(module) is None and os.environ.get("UNFORESEEN_REQUIRE_PYMDP") != "1":
        pytest.skip(f"{example.name} needs {module}: pip install './python[pymdp]'")
    env = {**os.environ, "UNFORESEEN_EXAMPLE_SMALL": "1", "SDL_VIDEODRIVER": "dummy", "PYTHONWARNINGS": "ignore"}
    out = subprocess.run([sys.executable, str(example)], cwd=tmp_path, env=env, capture_output=True, text=True,
                         timeout=600)
    assert out.returncode == 0, out.stderr[-3000:]
    assert out.stdout.strip(), "the example prints what it did"

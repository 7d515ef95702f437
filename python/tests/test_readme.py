"""Every Python block of the README (```python and ```py fences) runs as written, in order,
twice (a notebook cell run again), each run in a fresh namespace (a block must import what it uses: a reader may copy any one
of them), in a scratch folder with the repository's maps/ beside it, at small sizes: episodes capped at 300, learning at
600 steps. Blocks that import Stable-Baselines3
run where it is installed (UNFORESEEN_REQUIRE_SB3=1 fails instead of skipping them)."""

from __future__ import annotations

import ast
import builtins
import os
import re
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
README = REPO / "README.md"

#: Size caps: (pattern, replacement).
CAPS = [
    (r"\bepisodes=\d[\d_]*", "episodes=300"),
    (r"\.learn\(\d[\d_]*\)", ".learn(600)"),
    (r"range\(1, 11\)", "range(1, 3)"),
]


def python_blocks() -> list[str]:
    return re.findall(r"```(?:python|py)\n(.*?)```", README.read_text(), flags=re.S)


BLOCKS = python_blocks()


def unbound_names(code: str) -> set[str]:
    """Names `code` reads that nothing in it binds and that are not builtins (a missing
    import, even inside a function the run never calls). Scopes are not told apart: a
    name bound anywhere counts as bound."""
    tree = ast.parse(code)
    bound: set[str] = set(dir(builtins))
    loaded: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Name):
            (loaded if isinstance(node.ctx, ast.Load) else bound).add(node.id)
        elif isinstance(node, (ast.Import, ast.ImportFrom)):
            bound.update((a.asname or a.name).split(".")[0] for a in node.names)
        elif isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            bound.add(node.name)
        elif isinstance(node, ast.arg):
            bound.add(node.arg)
    return loaded - bound


def test_every_python_block_imports_what_it_uses():
    for i, code in enumerate(BLOCKS):
        assert not unbound_names(code), f"README Python block {i + 1} uses {unbound_names(code)} without importing"


def test_unbound_names_finds_a_missing_import():
    code = "def probs(q):\n    return np.exp(q)\n"
    assert unbound_names(code) == {"np"}
    assert unbound_names("import numpy as np\n" + code) == set()


def _needs_sb3(code: str) -> bool:
    return "stable_baselines3" in code


def _have_sb3() -> bool:
    try:
        import stable_baselines3  # noqa: F401
    except ImportError:
        return False
    return True


def test_the_readme_has_python_blocks():
    assert len(BLOCKS) >= 4


@pytest.mark.filterwarnings("ignore::DeprecationWarning")
@pytest.mark.filterwarnings("ignore::UserWarning")
@pytest.mark.parametrize("i", range(len(BLOCKS)), ids=[f"block{i + 1}" for i in range(len(BLOCKS))])
def test_python_block_of_the_readme_runs(i, tmp_path, monkeypatch):
    code = BLOCKS[i]
    if _needs_sb3(code) and not _have_sb3():
        if os.environ.get("UNFORESEEN_REQUIRE_SB3") == "1":
            pytest.fail("Stable-Baselines3 is required here (UNFORESEEN_REQUIRE_SB3=1)")
        pytest.skip("Stable-Baselines3 is not installed: pip install stable-baselines3")
    monkeypatch.chdir(tmp_path)
    (tmp_path / "maps").symlink_to(REPO / "maps")
    for pattern, repl in CAPS:
        code = re.sub(pattern, repl, code)
    compiled = compile(code, f"{README} (Python block {i + 1})", "exec")
    # Twice in one process and folder, as a notebook cell is run again: the second run
    # meets the first one's files and agents.
    exec(compiled, {})
    namespace: dict = {}
    exec(compiled, namespace)
    if i == 0:
        assert namespace["terminated"] or namespace["truncated"]

"""The README's Python example runs as written (training capped at 300 episodes)."""

from __future__ import annotations

import re
from pathlib import Path

README = Path(__file__).resolve().parents[2] / "README.md"


def test_readme_python_example_runs():
    blocks = re.findall(r"```python\n(.*?)```", README.read_text(), flags=re.S)
    assert blocks, "the README has a Python example"
    for code in blocks:
        code = re.sub(r"episodes=\d+", "episodes=300", code)
        namespace: dict = {}
        exec(compile(code, str(README), "exec"), namespace)
        assert namespace["terminated"] or namespace["truncated"]

"""The stub file `_unforeseen.pyi` names every class, method and function the extension
has, and nothing it lacks."""

from __future__ import annotations

import ast
from pathlib import Path

import unforeseen._unforeseen as ext

STUB = Path(__file__).resolve().parents[1] / "unforeseen" / "_unforeseen.pyi"


def test_stub_matches_the_extension():
    stub: dict[str, set[str] | None] = {}
    for node in ast.parse(STUB.read_text()).body:
        if isinstance(node, ast.ClassDef):
            stub[node.name] = {n.name for n in node.body if isinstance(n, ast.FunctionDef)}
        elif isinstance(node, ast.FunctionDef):
            stub[node.name] = None
    public = [n for n in dir(ext) if not n.startswith("_")]
    assert sorted(set(public) - set(stub)) == []
    assert sorted(n for n in stub if not hasattr(ext, n)) == []
    for name in public:
        obj = getattr(ext, name)
        if isinstance(obj, type):
            missing = [a for a in dir(obj) if not a.startswith("_") and a not in stub[name]]
            assert missing == [], (name, missing)

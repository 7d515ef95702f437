#!/usr/bin/env python3
"""Whether two batch results files (and the summaries beside them) are the same run's
results, field by field, timing aside: `python3 scripts/same_results.py A.jsonl B.jsonl`.
Prints every field that differs (at most 20) and exits 1 if any does, else prints the
count of lines and fields compared and exits 0."""

from __future__ import annotations

import json
import sys
from pathlib import Path

TIMING = "timing_us_per_tick"


def lines(path: Path) -> list[dict]:
    return [json.loads(line) for line in path.read_text().splitlines()]


def summary(path: Path) -> dict:
    s = json.loads(path.with_suffix(".summary.json").read_text())
    s.pop("results", None)  # the file's own name
    return s


def diff(a, b, where: str, out: list[str]) -> int:
    """Compares a and b recursively, skipping timing fields; returns the fields compared."""
    if isinstance(a, dict) and isinstance(b, dict):
        n = 0
        for k in sorted(set(a) | set(b)):
            if k == TIMING:
                continue
            if k not in a or k not in b:
                out.append(f"{where}.{k}: only in {'the first' if k in a else 'the second'}")
                continue
            n += diff(a[k], b[k], f"{where}.{k}", out)
        return n
    if isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            out.append(f"{where}: {len(a)} items against {len(b)}")
            return 1
        return sum(diff(x, y, f"{where}[{i}]", out) for i, (x, y) in enumerate(zip(a, b)))
    if a != b:
        out.append(f"{where}: {a!r} != {b!r}")
    return 1


def main() -> int:
    if len(sys.argv) != 3:
        print(__doc__, file=sys.stderr)
        return 2
    a, b = Path(sys.argv[1]), Path(sys.argv[2])
    out: list[str] = []
    la, lb = lines(a), lines(b)
    n = diff(la, lb, "line", out) + diff(summary(a), summary(b), "summary", out)
    for d in out[:20]:
        print(d)
    if out:
        print(f"{len(out)} difference(s) in {n} fields")
        return 1
    print(f"same results: {len(la)} lines (identity included) and the summary, {n} fields compared, timing aside")
    return 0


if __name__ == "__main__":
    sys.exit(main())

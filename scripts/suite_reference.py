#!/usr/bin/env python3
"""The CI suites' results kept byte for byte, timing aside: a reference results file per
suite in tests/suites/, and a check that a new run's file holds the same results.

  python3 scripts/suite_reference.py check REF.jsonl NEW.jsonl
  python3 scripts/suite_reference.py write NEW.jsonl REF.jsonl

`check` compares line by line: every field of the reference's line must be in the new
line with the same value (a new run may add fields: results files keep their keys and
add new ones); the timing field and the header's code identity (`program`, `agents`,
which hash the program's code) are not compared. It prints the first differences and
exits 1 if any. `write` stores a run as the reference, without those fields: run it, and
commit the change with its reason, when a change is meant to alter the suites' results."""

from __future__ import annotations

import json
import sys
from pathlib import Path

TIMING = "timing_us_per_tick"
CODE_IDENTITY = ("program", "agents")


def lines(path: Path) -> list[dict]:
    return [json.loads(line) for line in path.read_text().splitlines()]


def stripped(line: dict) -> dict:
    line = {k: v for k, v in line.items() if k != TIMING}
    if "run" in line:
        line["run"] = {k: v for k, v in line["run"].items() if k not in CODE_IDENTITY}
    return line


def covers(ref, new, where: str, out: list[str]) -> int:
    """Checks that `new` holds `ref` (dicts: every key of ref, recursively); returns the
    values compared."""
    if isinstance(ref, dict) and isinstance(new, dict):
        n = 0
        for k in sorted(ref):
            if k not in new:
                out.append(f"{where}.{k}: missing from the new run")
            else:
                n += covers(ref[k], new[k], f"{where}.{k}", out)
        return n
    if isinstance(ref, list) and isinstance(new, list):
        if len(ref) != len(new):
            out.append(f"{where}: {len(ref)} items in the reference, {len(new)} in the new run")
            return 1
        return sum(covers(x, y, f"{where}[{i}]", out) for i, (x, y) in enumerate(zip(ref, new)))
    if ref != new:
        out.append(f"{where}: reference {ref!r}, new run {new!r}")
    return 1


def main() -> int:
    if len(sys.argv) != 4 or sys.argv[1] not in ("check", "write"):
        print(__doc__, file=sys.stderr)
        return 2
    if sys.argv[1] == "write":
        new, ref = Path(sys.argv[2]), Path(sys.argv[3])
        ref.write_text("".join(json.dumps(stripped(l), separators=(",", ":")) + "\n" for l in lines(new)))
        print(f"wrote {ref} from {new}")
        return 0
    ref, new = Path(sys.argv[2]), Path(sys.argv[3])
    out: list[str] = []
    n = covers([stripped(l) for l in lines(ref)], [stripped(l) for l in lines(new)], "line", out)
    for d in out[:20]:
        print(d)
    if out:
        print(f"{new}: {len(out)} difference(s) from {ref} in {n} values (refresh it with `write` only if the change is meant)")
        return 1
    print(f"{new}: the results of {ref}, {n} values compared, timing aside")
    return 0


if __name__ == "__main__":
    sys.exit(main())

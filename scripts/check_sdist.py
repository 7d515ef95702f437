#!/usr/bin/env python3
# Usage: python3 scripts/check_sdist.py SDIST.tar.gz DEP_INFO   (exit status 1 on a problem)
"""Checks the Python package's sdist (`maturin sdist -m python/Cargo.toml`) without
building a wheel from it, which costs a full release build of the extension (about 5 min
on two cores; the release workflow does it):

1. cargo reads every manifest of the unpacked sdist: `cargo metadata --locked --offline`
   on its python/Cargo.toml, which parses the binding's manifest, the path crates'
   manifests and the workspace root they inherit from (the step a build from the sdist
   failed at when the root manifest named targets whose files the sdist lacks);
2. every file of the repository that the last build of the extension read (DEP_INFO:
   python/target/release/lib_unforeseen.d, cargo's list of the sources, the files
   `include_str!` embeds and the build script's inputs) is in the sdist, at the same path;
3. every file of the Python package (python/unforeseen/, as git tracks it) is in it.

The root Cargo.lock is the one file of the build allowed to be missing: maturin packs
the binding's own python/Cargo.lock, and harness/build.rs hashes the root one, when it
exists, into the code fingerprint (agent cache keys, the program of `batch --resume`).
A wheel built from the sdist therefore has another fingerprint than one built from the
repository; its build and its results are the same.
"""
import os
import subprocess
import sys
import tarfile
import tempfile

ALLOWED_MISSING = {"Cargo.lock"}


def dep_info_paths(path):
    """The prerequisites of a Makefile-style dep-info file (`target: a b\\ c ...`)."""
    with open(path, encoding="utf-8") as f:
        text = f.read()
    rule = text.split("\n\n")[0]  # the artifact's own rule comes first
    _, _, deps = rule.partition(": ")
    out, cur, i = [], "", 0
    deps = deps.replace("\\\n", " ")
    while i < len(deps):
        ch = deps[i]
        if ch == "\\" and i + 1 < len(deps) and deps[i + 1] == " ":
            cur += " "
            i += 2
            continue
        if ch in " \n":
            if cur:
                out.append(cur)
            cur = ""
        else:
            cur += ch
        i += 1
    if cur:
        out.append(cur)
    return out


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    sdist, dep_info = sys.argv[1], sys.argv[2]
    repo = os.path.realpath(os.path.join(os.path.dirname(__file__), ".."))
    problems = []
    with tarfile.open(sdist) as tar:
        names = tar.getnames()
        top = names[0].split("/")[0]
        files = {n[len(top) + 1 :] for n in names if n.startswith(top + "/")}
        dirs = {os.path.dirname(f) for f in files}
        while "" not in dirs and dirs:
            dirs |= {os.path.dirname(d) for d in dirs}
        with tempfile.TemporaryDirectory() as tmp:
            if hasattr(tarfile, "data_filter"):  # Python >= 3.10.12 / 3.11.4
                tar.extractall(tmp, filter="data")
            else:
                tar.extractall(tmp)
            manifest = os.path.join(tmp, top, "python", "Cargo.toml")
            run = subprocess.run(
                ["cargo", "metadata", "--format-version", "1", "--locked", "--offline",
                 "--manifest-path", manifest],
                capture_output=True, text=True,
            )
            if run.returncode != 0:
                problems.append("cargo cannot read the sdist's manifests:\n" + run.stderr.strip())

    # 2. what the extension's build read
    needed = 0
    for p in dep_info_paths(dep_info):
        real = os.path.normpath(p)
        if not real.startswith(repo + os.sep):
            continue  # the registry's crates, the standard library
        rel = os.path.relpath(real, repo)
        if rel.startswith(os.path.join("python", "target") + os.sep):
            continue  # generated (OUT_DIR)
        needed += 1
        if rel in files or rel in dirs or rel in ALLOWED_MISSING:
            continue
        problems.append(f"the build reads {rel}, which the sdist lacks")
    if needed < 50:
        problems.append(f"{dep_info} names only {needed} files of the repository: not the extension's dep-info?")

    # 3. the Python package
    tracked = subprocess.run(
        ["git", "ls-files", "python/unforeseen"], cwd=repo, capture_output=True, text=True, check=True
    ).stdout.split()
    for rel in tracked:
        if rel[len("python/"):] not in files:
            problems.append(f"the sdist lacks {rel} (as {rel[len('python/'):]})")

    for p in problems:
        print("sdist:", p, file=sys.stderr)
    if problems:
        sys.exit(1)
    print(f"sdist {os.path.basename(sdist)}: {len(files)} files; cargo reads its manifests; "
          f"it holds the {needed} files of the repository the extension's build reads "
          f"(but the root Cargo.lock) and the {len(tracked)} of the Python package")


if __name__ == "__main__":
    main()

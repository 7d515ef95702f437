#!/usr/bin/env python3
# Usage: python3 scripts/module_imports.py .   (exit status 1 on a cycle or an upward import)
"""Module-level imports inside each crate of the workspace (and of the Python binding,
python/src): an edge a -> b when a's code (comments stripped) names `crate::b...` (also
inside `use crate::{...}` groups) or `super::b...`.

Fails on:
* a cycle: a strongly connected component with more than one file;
* an import that runs up a floor of the harness (FLOORS, lowest first; docs/ARCHITECTURE.md
  §1): a module may import its own floor and the floors below, never one above;
* a `pub mod` inside a part of the harness (FACES) that is not one of the part's named
  namespaces: a part's files are `pub(crate)` behind its `mod.rs`, its one face."""
import os, re, sys
root = sys.argv[1]
crates = {'unforeseen': 'src', 'harness': 'harness/src', 'sim': 'sim/src', 'agent': 'agent/src', 'discretizer': 'discretizer/src', 'env': 'env/src', 'python': 'python/src'}
# The harness's floors, lowest first: each entry is a module or a folder (every module
# under it). The output guard sits below the jobs it guards; the tests' fixtures on top.
FLOORS = {'harness': [
    ['error', 'files', 'progress', 'limits', 'stats'],
    ['maps', 'overrides', 'episodes'],
    ['training'],
    ['reports'],
    ['runs::outputs', 'runs::file_kinds'],
    ['runs'],
    ['fixtures'],
]}
# The harness's parts whose mod.rs is their one face, and the modules inside them that
# are public namespaces (every other module inside is `pub(crate)` or private).
FACES = {
    'harness/src/episodes/mod.rs': {'survivability'},
    'harness/src/training/mod.rs': {'agent_file'},
    'harness/src/reports/mod.rs': {'figures'},
    'harness/src/runs/batch/mod.rs': set(),
    'harness/src/runs/compare/mod.rs': set(),
    'harness/src/runs/search/mod.rs': set(),
}
def floor_of(floors, module):
    best, depth = None, -1
    for i, floor in enumerate(floors):
        for prefix in floor:
            if (module == prefix or module.startswith(prefix + '::')) and prefix.count('::') > depth:
                best, depth = i, prefix.count('::')
    return best
for extra in sys.argv[2:]:
    crates[extra] = extra + '/src'
def strip(text):
    text = re.sub(r'/\*.*?\*/', '', text, flags=re.S)
    text = re.sub(r'"(\\.|[^"\\])*"', '""', text)
    return re.sub(r'//[^\n]*', '', text)
def mod_of(rel):
    rel = rel[:-3]
    if rel in ('lib', 'main'): return ''
    if rel.endswith('/mod'): rel = rel[:-4]
    return rel.replace('/', '::')
def paths_in_group(prefix, body):
    # split a `{a, b::{c, d}, e::f}` group at top level
    out, depth, cur = [], 0, ''
    for ch in body:
        if ch == '{': depth += 1
        elif ch == '}': depth -= 1
        if ch == ',' and depth == 0:
            out.append(cur); cur = ''
        else:
            cur += ch
    out.append(cur)
    res = []
    for p in out:
        p = p.strip()
        if not p: continue
        m = re.match(r'([\w:]*?)::\{(.*)\}$', p, re.S)
        if m: res += paths_in_group(prefix + [x for x in m.group(1).split('::') if x], m.group(2))
        else: res.append(prefix + [x for x in p.split(' as ')[0].strip().split('::') if x])
    return res
total = 0
for name, src in crates.items():
    d = os.path.join(root, src)
    if not os.path.isdir(d): continue
    files = {}
    for dp, _, fs in os.walk(d):
        for f in fs:
            if f.endswith('.rs'):
                rel = os.path.relpath(os.path.join(dp, f), d)
                files[mod_of(rel)] = strip(open(os.path.join(dp, f)).read())
    mods = set(files)
    def resolve(segs):
        best = None
        for i in range(1, len(segs) + 1):
            cand = '::'.join(segs[:i])
            if cand in mods: best = cand
        return best
    edges = {m: set() for m in mods}
    for m, text in files.items():
        refs = []
        for g in re.finditer(r'\bcrate::\{(.*?)\};', text, re.S):
            refs += paths_in_group([], g.group(1))
        for g in re.finditer(r'\bcrate((?:::\w+)+)', text):
            refs.append([x for x in g.group(1).split('::') if x])
        parent = m.rsplit('::', 1)[0] if '::' in m else ''
        for g in re.finditer(r'\bsuper((?:::\w+)+)', text):
            segs = [x for x in g.group(1).split('::') if x]
            refs.append(([parent] if parent else []) + segs)
            if not resolve(refs[-1]): refs[-1] = [parent] if parent else []
        for r in refs:
            t = resolve(r) if r else None
            if t is None and r and parent == '' and False: pass
            if t is not None and t != m and t != '':
                edges[m].add(t)
    # Tarjan
    index, low, stack, on, sccs, i = {}, {}, [], set(), [], [0]
    sys.setrecursionlimit(10000)
    def visit(v):
        index[v] = low[v] = i[0]; i[0] += 1; stack.append(v); on.add(v)
        for w in edges[v]:
            if w not in index: visit(w); low[v] = min(low[v], low[w])
            elif w in on: low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop(); on.discard(w); comp.append(w)
                if w == v: break
            if len(comp) > 1: sccs.append(comp)
    for v in sorted(mods):
        if v not in index: visit(v)
    print(f'{name}: {len(mods)} files, {sum(map(len, edges.values()))} edges, cycles: {sccs or "none"}')
    for c in sccs:
        for a in c:
            print('   ', a, '->', sorted(e for e in edges[a] if e in c))
    total += len(sccs)
    floors = FLOORS.get(name)
    if floors:
        upward = []
        for a in sorted(mods):
            fa = floor_of(floors, a)
            if a and fa is None:
                upward.append(f'{a}: on no floor (add it to FLOORS)')
                continue
            for b in sorted(edges[a]):
                fb = floor_of(floors, b)
                if fa is not None and fb is not None and fb > fa:
                    upward.append(f'{a} (floor {fa}) -> {b} (floor {fb})')
        print(f'{name}: {len(floors)} floors, upward imports: {upward or "none"}')
        for u in upward:
            print('   ', u)
        total += len(upward)
faces = []
for face, namespaces in FACES.items():
    for m in re.findall(r'^pub mod (\w+);', strip(open(os.path.join(root, face)).read()), re.M):
        if m not in namespaces:
            faces.append(f'{face}: `pub mod {m}` (make it pub(crate) and re-export what other crates use)')
print(f'harness: {len(FACES)} faces, public modules behind them: {faces or "none"}')
for f in faces:
    print('   ', f)
total += len(faces)
sys.exit(1 if total else 0)

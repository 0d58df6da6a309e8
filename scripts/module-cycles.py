#!/usr/bin/env python3
"""Lists import cycles among the top-level modules of each crate under codec/ and server/.

A module `a` depends on `b` when a file of `a` names `crate::b` (in a `use`
or a path). Unit-test code (after `#[cfg(test)]`) is left out: tests may
reach anywhere. Exits 1 when a cycle exists.
"""
import pathlib
import re
import sys

root = pathlib.Path(__file__).resolve().parent.parent
crates = [p.parent for p in root.glob("codec/*/src") if (p / "lib.rs").exists()]
crates += [root / "server"]
found = False
for crate in sorted(crates):
    src = crate / "src"
    graph = {}
    for f in src.rglob("*.rs"):
        rel = f.relative_to(src).parts
        if rel[0] in ("lib.rs", "main.rs", "bin"):
            continue
        module = rel[0].removesuffix(".rs")
        text = f.read_text()
        text = text.split("#[cfg(test)]")[0]
        text = re.sub(r"//[^\n]*", "", text)
        # `use crate::{a, b::c}` and `crate::a::…` paths
        targets = set(re.findall(r"crate::([a-z_][a-z0-9_]*)", text))
        for group in re.findall(r"crate::\{([^}]*)\}", text):
            targets |= set(re.findall(r"(?:^|,)\s*([a-z_][a-z0-9_]*)", group))
        graph.setdefault(module, set()).update(t for t in targets if t != module)
    modules = set(graph)
    graph = {m: {t for t in ts if t in modules} for m, ts in graph.items()}
    # Tarjan's strongly connected components.
    index, low, stack, on, sccs, counter = {}, {}, [], set(), [], [0]
    def visit(v):
        index[v] = low[v] = counter[0]; counter[0] += 1
        stack.append(v); on.add(v)
        for w in graph.get(v, ()):
            if w not in index:
                visit(w); low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            scc = []
            while True:
                w = stack.pop(); on.discard(w); scc.append(w)
                if w == v:
                    break
            if len(scc) > 1:
                sccs.append(sorted(scc))
    sys.setrecursionlimit(10000)
    for v in sorted(graph):
        if v not in index:
            visit(v)
    name = crate.relative_to(root)
    for scc in sccs:
        found = True
        edges = [f"{a}->{b}" for a in scc for b in sorted(graph[a]) if b in scc]
        print(f"{name}: cycle among {', '.join(scc)} ({'; '.join(edges)})")
    if not sccs:
        print(f"{name}: {len(graph)} modules, no cycle")
sys.exit(1 if found else 0)

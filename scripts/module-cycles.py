#!/usr/bin/env python3
"""Lists import cycles among sibling modules of each crate under codec/, server/ and tests/load.

Siblings are the top-level modules of a crate, and the children of each
directory module (`encoder/{coding,conquest,…}`). Module `a` depends on its
sibling `b` when a file of `a` names `crate::…::b` or `super::b` (in a `use`
or a path). A parent and its own children may name each other (`mod.rs`
re-exports, children read the parent's options). Unit-test code (after
`#[cfg(test)]`) is left out: tests may reach anywhere. Exits 1 when a cycle
exists.
"""
import pathlib
import re
import sys

root = pathlib.Path(__file__).resolve().parent.parent
crates = [p.parent for p in root.glob("codec/*/src") if (p / "lib.rs").exists()]
crates += [root / "server", root / "tests" / "load"]


def module_path(src, f):
    """`encoder/coding.rs` -> ("encoder", "coding"); `encoder/mod.rs` -> ("encoder",)."""
    parts = list(f.relative_to(src).with_suffix("").parts)
    if parts[-1] == "mod" or (len(parts) == 1 and parts[0] in ("lib", "main")):
        parts = parts[:-1]
    return tuple(parts)


def references(text, here):
    """Absolute module paths a file's code names."""
    text = re.sub(r"//[^\n]*", "", text.split("#[cfg(test)]")[0])
    found = set()
    for m in re.finditer(r"\b(crate|super)((?:::[a-z_][a-z0-9_]*)+)", text):
        names = m.group(2).split("::")[1:]
        base = () if m.group(1) == "crate" else here[:-1]
        found.add(base + tuple(names))
    for m in re.finditer(r"\b(crate|super)((?:::[a-z_][a-z0-9_]*)*)::\{([^}]*)\}", text):
        prefix = m.group(2).split("::")[1:] if m.group(2) else []
        base = () if m.group(1) == "crate" else here[:-1]
        for name in re.findall(r"(?:^|,)\s*([a-z_][a-z0-9_]*)", m.group(3)):
            found.add(base + tuple(prefix) + (name,))
    return found


def cycles(graph):
    """Strongly connected components of more than one node (Tarjan)."""
    index, low, stack, on, out, counter = {}, {}, [], set(), [], [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in graph.get(v, ()):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            scc = []
            while True:
                w = stack.pop()
                on.discard(w)
                scc.append(w)
                if w == v:
                    break
            if len(scc) > 1:
                out.append(sorted(scc))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return out


sys.setrecursionlimit(10000)
found = False
for crate in sorted(crates):
    src = crate / "src"
    modules = {module_path(src, f): f for f in src.rglob("*.rs") if "bin" not in f.relative_to(src).parts}
    # parent -> {child -> set(sibling children it names)}
    siblings = {}
    for here, f in modules.items():
        if not here:
            continue
        parent = here[:-1]
        group = siblings.setdefault(parent, {})
        group.setdefault(here[-1], set())
        for target in references(f.read_text(), here):
            # the sibling of `here` that `target` lies in, if any
            if len(target) > len(parent) and target[: len(parent)] == parent:
                sibling = target[len(parent)]
                if sibling != here[-1] and parent + (sibling,) in modules:
                    group[here[-1]].add(sibling)
    name = crate.relative_to(root)
    count = 0
    for parent, graph in sorted(siblings.items()):
        count += len(graph)
        for scc in cycles(graph):
            found = True
            edges = [f"{a}->{b}" for a in scc for b in sorted(graph[a]) if b in scc]
            where = "::".join(parent) or "crate root"
            print(f"{name}: cycle under {where} among {', '.join(scc)} ({'; '.join(edges)})")
    print(f"{name}: {count} modules checked")
sys.exit(1 if found else 0)

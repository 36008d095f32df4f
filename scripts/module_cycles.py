#!/usr/bin/env python3
"""Reports import cycles between the modules of a Rust crate, at two levels.

Usage: python3 scripts/module_cycles.py SRC_DIR...   (`.ci/run` checks src and support/src)

- Top-level modules: a file SRC/NAME.rs or a folder SRC/NAME/; an edge A -> B when a file
  of A names `crate::B` (in a `use` line or in code, grouped imports included). This is
  the workplace's `module-cycles` tool, kept here so that CI runs it on a clean clone.
- The files of one folder: SRC/DIR/NAME.rs (or SRC/DIR/NAME/); an edge A -> B when a file
  of A names `super::B`, or `crate::DIR::B`.
Prints each cycle (a strongly connected component of more than one module) with the lines
that tie it, and exits 1 when there is any.
"""
import os
import re
import sys
from collections import defaultdict


def modules(folder):
    """The modules of `folder`: {name: [files]}, `mod.rs`, `lib.rs` and `main.rs` aside."""
    mods = {}
    for entry in sorted(os.listdir(folder)):
        path = os.path.join(folder, entry)
        if entry.endswith(".rs") and entry not in ("lib.rs", "main.rs", "mod.rs"):
            mods[entry[:-3]] = [path]
        elif os.path.isdir(path):
            files = []
            for root, _, names in os.walk(path):
                files += [os.path.join(root, n) for n in sorted(names) if n.endswith(".rs")]
            mods[entry] = files
    return mods


def edges_of(mods, prefixes):
    """Edges between `mods`, where a path starting with one of `prefixes` names a module."""
    edges = defaultdict(lambda: defaultdict(list))
    for prefix in prefixes:
        single = re.compile(r"\b" + re.escape(prefix) + r"([a-z_][a-z0-9_]*)")
        grouped = re.compile(r"\b" + re.escape(prefix) + r"\{([^}]*)\}", re.S)
        for m, files in mods.items():
            for f in files:
                text = open(f, encoding="utf-8").read()
                for lineno, line in enumerate(text.splitlines(), 1):
                    if line.lstrip().startswith("//"):
                        continue
                    for target in single.findall(line):
                        if target in mods and target != m:
                            edges[m][target].append(f"{f}:{lineno}")
                for block in grouped.findall(text):
                    for target in re.findall(r"(?:^|[,{\s])([a-z_][a-z0-9_]*)\s*(?:::|,|$)", block):
                        if target in mods and target != m:
                            edges[m][target].append(f"{f}: {prefix}{{..{target}..}}")
    return edges


def cycles(mods, edges):
    """Tarjan's strongly connected components of more than one module."""
    index, low, on, stack, found, counter = {}, {}, set(), [], [], [0]

    def strong(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in edges[v]:
            if w not in index:
                strong(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                found.append(sorted(comp))

    sys.setrecursionlimit(10000)
    for v in mods:
        if v not in index:
            strong(v)
    return found


def report(what, mods, edges):
    """Prints the cycles of one level; true when there is none."""
    found = cycles(mods, edges)
    for c in found:
        print(f"cycle in {what}: " + ", ".join(c))
        for a in c:
            for b in c:
                if b in edges[a]:
                    where = edges[a][b]
                    more = f" (+{len(where) - 1} more)" if len(where) > 1 else ""
                    print(f"  {a} -> {b}: {where[0]}{more}")
    return not found


def main():
    ok = True
    for src in sys.argv[1:] or ["src"]:
        top = modules(src)
        ok &= report(f"{src} (top-level modules)", top, edges_of(top, ["crate::"]))
        for name, files in top.items():
            folder = os.path.join(src, name)
            if os.path.isdir(folder):
                inner = modules(folder)
                ok &= report(folder, inner, edges_of(inner, ["super::", f"crate::{name}::"]))
    if ok:
        print("no cycles between modules: " + ", ".join(sys.argv[1:] or ["src"]))
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()

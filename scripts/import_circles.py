#!/usr/bin/env python3
"""Finds import circles between sibling modules inside each crate of the workspace.

A module `a` depends on a sibling `b` when any file under `a` names an item of `b` through a
`use` (not a `pub use` re-export, which only forwards a name) or a qualified path
(`crate::b::…`, `super::b::…`). A child naming its parent's items is not a sibling edge.
Exit status 1 and one line per circle when any sibling graph has a cycle.

    python3 scripts/import_circles.py [crates_dir]
"""
import os
import re
import sys


def module_of(src, path):
    rel = os.path.relpath(path, src)[:-3].split(os.sep)
    if rel[-1] in ("lib", "main", "mod"):
        rel = rel[:-1]
    return tuple(rel)


def strip_comments(text):
    text = re.sub(r"/\*.*?\*/", "", text, flags=re.S)
    text = re.sub(r"//[^\n]*", "", text)
    text = re.sub(r'r#*"(?:.|\n)*?"#*', '""', text)
    text = re.sub(r'"(?:\\.|[^"\\])*"', '""', text)
    return text


def expand_use(tree):
    """`a::{b, c::{d, e}}` -> ['a::b', 'a::c::d', 'a::c::e']"""
    tree = tree.strip()
    i = tree.find("{")
    if i < 0:
        return [tree.split(" as ")[0].strip()]
    prefix = tree[:i]
    inner = tree[i + 1: tree.rfind("}")]
    parts, depth, cur = [], 0, ""
    for ch in inner:
        if ch == "," and depth == 0:
            parts.append(cur)
            cur = ""
            continue
        depth += ch == "{"
        depth -= ch == "}"
        cur += ch
    parts.append(cur)
    out = []
    for p in parts:
        if p.strip():
            out += [prefix + q for q in expand_use(p)]
    return out


def paths_in(text):
    """Module paths named by a file: (path, is_reexport)."""
    text = strip_comments(text)
    found = []
    for m in re.finditer(r"(\bpub(?:\([^)]*\))?\s+)?\buse\s+([^;]+);", text):
        for p in expand_use(m.group(2)):
            found.append((p.replace(" ", ""), m.group(1) is not None))
    body = re.sub(r"\buse\s+[^;]+;", "", text)
    for m in re.finditer(r"\b((?:crate|super|self)(?:::(?:super|[A-Za-z_][A-Za-z0-9_]*))+)", body):
        found.append((m.group(1), False))
    return found


def resolve(path, here, is_dir_mod, modules):
    segs = path.split("::")
    if segs[0] == "crate":
        base, segs = (), segs[1:]
    elif segs[0] in ("self", "super"):
        base = here if is_dir_mod or segs[0] == "super" else here
        # `self` in a file module is the module itself; `super` its parent.
        base = here
        while segs and segs[0] in ("self", "super"):
            if segs[0] == "super":
                base = base[:-1]
            segs = segs[1:]
    else:
        return None
    best = base
    cur = base
    for s in segs:
        cur = cur + (s,)
        if cur in modules:
            best = cur
        else:
            break
    return best


def crate_cycles(src):
    files = []
    for root, _, names in os.walk(src):
        for n in names:
            if n.endswith(".rs"):
                files.append(os.path.join(root, n))
    modules = {module_of(src, f) for f in files}
    # a module's directory may hold `bin/` etc.; keep only real modules
    edges = {}
    for f in files:
        here = module_of(src, f)
        is_dir_mod = os.path.basename(f) in ("mod.rs", "lib.rs", "main.rs")
        with open(f, encoding="utf-8") as fh:
            text = fh.read()
        for p, reexport in paths_in(text):
            if reexport:
                continue
            target = resolve(p, here, is_dir_mod, modules)
            if target is None or target == here:
                continue
            k = 0
            while k < min(len(here), len(target)) and here[k] == target[k]:
                k += 1
            if k == len(here) or k == len(target):
                continue  # parent and child
            a, b = here[: k + 1], target[: k + 1]
            edges.setdefault(a, set()).add(b)
    # cycles: strongly connected components with more than one node
    index, low, stack, on, sccs = {}, {}, [], set(), []
    counter = [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in sorted(edges.get(v, ())):
            if w not in index:
                visit(w)
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
                sccs.append(sorted(comp))

    sys.setrecursionlimit(10000)
    for v in sorted(edges):
        if v not in index:
            visit(v)
    return sccs, edges


def main():
    crates = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..", "crates")
    bad = 0
    for c in sorted(os.listdir(crates)):
        src = os.path.join(crates, c, "src")
        if not os.path.isdir(src):
            continue
        sccs, edges = crate_cycles(src)
        for comp in sccs:
            bad += 1
            names = ["::".join(m) for m in comp]
            detail = []
            for a in comp:
                for b in sorted(edges.get(a, ())):
                    if b in comp:
                        detail.append("::".join(a) + " -> " + "::".join(b))
            print(f"{c}: import circle between {', '.join(names)} ({'; '.join(detail)})")
    if bad:
        sys.exit(1)
    print("no import circles")


if __name__ == "__main__":
    main()

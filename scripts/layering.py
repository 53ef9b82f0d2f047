#!/usr/bin/env python3
"""The layering check of the workspace: dependencies run one way, between crates and inside them.

Three rules, each failing with one line per offence (exit status 1):

1. **Crates.** Every crate's `[dependencies]` on workspace crates must be exactly those that
   `ALLOWED` grants it (the arrows of `docs/architecture.md`: types <- engine <- devices <-
   sessions (haptic-loop) <- lesson, play <- cli <- the wheel (ot-py runs the program as its
   `nanohaptics` command); world crates know nothing of devices, logging, sound or Python; the
   engine knows no world, format, renderer or server, whatever ALLOWED says (`NEVER`)): a
   dependency the map does not grant fails, and so does a grant
   the crate does not use (the map lists only the edges in use). A crate missing from
   `ALLOWED` fails too: a new crate states its place. A dev-dependency may point anywhere
   (a test may drive a crate from above) except into a cycle: a crate A dev-depending on B
   where B depends on A through `[dependencies]` (directly or not) fails, naming the cycle.
2. **Import circles.** Inside each crate, sibling modules must not import each other in a
   circle. A module `a` depends on a sibling `b` when any file under `a` names an item of `b`
   through a `use` (not a `pub use` re-export, which only forwards a name) or a qualified path
   (`crate::b::…`, `super::b::…`). A child naming its parent's items is not a sibling edge.
3. **Upward imports.** For the crates listed in `RANKS`, the top-level modules are ranked from
   the bottom up; a module must not import one ranked above it. A top-level module missing
   from the crate's list fails: a new module states its place.

    python3 scripts/layering.py [crates_dir]
"""
import os
import re
import sys
import tomllib

# Which workspace crates each crate depends on ([dependencies] only): exactly these, no more,
# no fewer (dev-dependencies are not listed; they must only not close a cycle).
ALLOWED = {
    "world-form": set(),
    "ot-physics": {"world-form"},
    "ot-envelope": {"ot-physics", "world-form"},
    # The brick world fills the one local-model type (haptic_types::local) itself.
    "brickworld": {"haptic-types", "world-form"},
    "nanoworld": {"world-form"},
    "haptic-types": {"world-form"},
    "picture": set(),
    "webguard": set(),
    "chart": {"picture"},
    "render": {"haptic-types", "picture", "world-form"},
    "nanohaptics-recording": {"haptic-types", "world-form"},
    # The engine knows no world, no file format, no renderer and no server (NEVER below).
    "haptic-engine": {"haptic-types", "world-form"},
    "haptic-devices": {"haptic-engine", "haptic-types", "world-form"},
    "haptic-loop": {
        "brickworld", "haptic-devices", "haptic-engine", "haptic-types", "nanohaptics-recording",
        "nanoworld", "ot-envelope", "ot-physics", "render", "webguard", "world-form",
    },
    "nanohaptics-lesson": {
        "brickworld", "chart", "haptic-devices", "haptic-loop", "nanohaptics-recording",
        "nanoworld", "world-form",
    },
    # Lesson files, the built-in module, the step evaluator and the progress: scenes are read
    # through the sessions crate (built-in names, files, switches), so a page can drive a lesson
    # without the lesson report's figures; the class report draws its two charts with `chart`.
    "nanohaptics-teaching": {"chart", "haptic-engine", "haptic-loop", "haptic-types", "world-form"},
    # The page runs a lesson (`play --lesson`): lesson files, the evaluator and the progress.
    "nanohaptics-play": {
        "haptic-devices", "haptic-engine", "haptic-loop", "haptic-types", "nanohaptics-recording",
        "nanohaptics-teaching", "render", "webguard", "world-form",
    },
    "nanohaptics-cli": {
        "haptic-devices", "haptic-engine", "haptic-loop", "haptic-types", "nanohaptics-lesson",
        "nanohaptics-play", "nanohaptics-recording", "nanohaptics-teaching", "render", "world-form",
    },
    # The wheel sits on top: besides its bindings it carries the whole program (the
    # `nanohaptics` command of `pip install nanohaptics`, docs/python.md), so it depends on the
    # cli crate and nothing depends on it.
    "ot-py": {
        "brickworld", "haptic-devices", "haptic-engine", "haptic-loop", "haptic-types", "nanohaptics-cli",
        "nanohaptics-recording", "nanoworld", "ot-envelope", "ot-physics", "world-form",
    },
    "nanohaptics-fuzz": {
        "brickworld", "haptic-devices", "haptic-engine", "haptic-loop", "haptic-types", "nanohaptics-play",
        "nanohaptics-recording", "nanoworld", "ot-envelope", "webguard", "world-form",
    },
    "bench-harness": {"chart", "world-form"},
}

# What a crate must never depend on, whatever ALLOWED grants it: the engine (the tick, the Scene
# trait, the loop config, the runner, the sinks' interface, the header, the pacing) knows no
# world, no file format, no renderer, no device protocol and no server.
NEVER = {
    "haptic-engine": {
        "brickworld", "nanoworld", "ot-envelope", "ot-physics", "nanohaptics-recording",
        "render", "picture", "chart", "webguard", "haptic-devices", "haptic-loop",
        "nanohaptics-play", "nanohaptics-lesson", "nanohaptics-cli",
    },
}

# Top-level modules of a crate from the bottom up (one list entry may hold several modules of
# the same rank, written "a b"); a module may import only modules of its rank or below.
RANKS = {
    "haptic-engine": [
        "check realtime",
        "timing header scene loop_config",
        "haptic pacing wakeup clock",
        "sink",
        "totals",
        "runner",
    ],
    "haptic-loop": [
        "scene",
        "encode arrays",
        "record_sink replay_device live",
        "error",
        "replay closed_loop sinks",
        "builtin mwidth",
        "setup",
        "session",
        "stepper sound media",
    ],
    "nanohaptics-recording": [
        "channels",
        "foxglove_out parse encode",
        "reader writer",
        "edit",
    ],
    "haptic-devices": [
        "mechanics grip plant link local",
        "script",
        "operator modelled linked",
        "bridge",
        "source",
    ],
}


def dep_names(table, kind):
    """The package names a manifest lists under `kind` (`dependencies` or
    `dev-dependencies`), its target-specific tables included; a renamed dependency counts
    by its package."""
    tables = [table.get(kind, {})]
    tables += [t.get(kind, {}) for t in table.get("target", {}).values()]
    out = set()
    for deps in tables:
        for key, spec in deps.items():
            out.add(spec.get("package", key) if isinstance(spec, dict) else key)
    return out


def crate_deps(crates):
    """{crate name: (Cargo.toml path, workspace crates in [dependencies], in
    [dev-dependencies])}."""
    out = {}
    manifests = {}
    for c in sorted(os.listdir(crates)):
        m = os.path.join(crates, c, "Cargo.toml")
        if os.path.isfile(m):
            with open(m, "rb") as fh:
                manifests[m] = tomllib.load(fh)
    names = {t["package"]["name"] for t in manifests.values()}
    for m, t in manifests.items():
        deps = dep_names(t, "dependencies") & names
        dev = dep_names(t, "dev-dependencies") & names
        out[t["package"]["name"]] = (m, deps, dev)
    return out


def dependency_path(crates, start, goal):
    """The shortest chain of [dependencies] from `start` to `goal` (both included), or None."""
    prev = {start: None}
    queue = [start]
    for here in queue:
        if here == goal:
            path = []
            while here is not None:
                path.append(here)
                here = prev[here]
            return path[::-1]
        for d in sorted(crates.get(here, (None, set(), set()))[1]):
            if d not in prev:
                prev[d] = here
                queue.append(d)
    return None


def crate_offences(crates):
    bad = []
    deps_of = crate_deps(crates)
    for name, (path, deps, dev) in sorted(deps_of.items()):
        for d in sorted((deps | ALLOWED.get(name, set())) & NEVER.get(name, set())):
            bad.append(f"{path}: `{name}` must never depend on `{d}` (NEVER, scripts/layering.py)")
        if name not in ALLOWED:
            bad.append(f"{path}: crate `{name}` has no place in ALLOWED (scripts/layering.py): "
                       "add it with the crates it depends on")
        else:
            for d in sorted(deps - ALLOWED[name]):
                bad.append(f"{path}: `{name}` must not depend on `{d}` "
                           f"(allowed: {', '.join(sorted(ALLOWED[name])) or 'no workspace crate'})")
            for d in sorted(ALLOWED[name] - deps):
                bad.append(f"{path}: ALLOWED (scripts/layering.py) grants `{name}` `{d}`, which "
                           "its [dependencies] do not use: remove the grant")
        for d in sorted(dev):
            back = dependency_path(deps_of, d, name)
            if back is not None:
                chain = " -> ".join(back)
                bad.append(f"{path}: dev-dependency cycle: `{name}` dev-depends on `{d}`, and "
                           f"{chain} through [dependencies]")
    return bad


def upward_offences(crate, src, edges):
    ranks = {}
    for i, row in enumerate(RANKS[crate]):
        for m in row.split():
            ranks[m] = i
    bad = []
    top = {f[:-3] if f.endswith(".rs") else f for f in os.listdir(src)} - {"lib", "main", "bin"}
    for m in sorted(top - set(ranks)):
        bad.append(f"{crate}: module `{m}` has no rank in RANKS (scripts/layering.py): add it")
    for a in sorted(edges):
        for b in sorted(edges[a]):
            if len(a) == 1 and len(b) == 1 and a[0] in ranks and b[0] in ranks \
                    and ranks[b[0]] > ranks[a[0]]:
                bad.append(f"{crate}: `{a[0]}` imports `{b[0]}`, a module above it")
    return bad


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
    pkg = {os.path.basename(os.path.dirname(m)): n for n, (m, _, _) in crate_deps(crates).items()}
    for line in crate_offences(crates):
        bad += 1
        print(line)
    for c in sorted(os.listdir(crates)):
        src = os.path.join(crates, c, "src")
        if not os.path.isdir(src):
            continue
        sccs, edges = crate_cycles(src)
        name = pkg.get(c, c)
        if name in RANKS:
            for line in upward_offences(name, src, edges):
                bad += 1
                print(line)
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
    print(f"layering: {len(pkg)} crates, dependencies one way and as mapped, no dev-dependency "
          "cycles, no import circles, no upward imports")


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""Files and functions a newcomer can read: no Rust library or program source file over 700
lines and no function over 100 lines outside tests (a `tests/` folder, a `tests.rs` module, a
`#[cfg(test)] mod`). The benchmarks' report programs (`examples/`, `benches/`) are scripts
that print tables and are not held to it.

Fails (exit status 1) with one line per offence: the file and its lines, or the function, where
it starts and its lines.

    python3 scripts/sizes.py [repository]
"""
import os
import re
import subprocess
import sys

MAX_FILE_LINES = 700
MAX_FN_LINES = 100

FN = re.compile(r"\s*(pub(\([^)]*\))?\s+)?(const\s+)?(async\s+)?(unsafe\s+)?fn\s+(\w+)")


def is_checked(path):
    """Library and program sources: not tests, not the report programs."""
    parts = path.split("/")
    if "tests" in parts[:-1] or parts[-1] == "tests.rs":
        return False
    return not ({"examples", "benches"} & set(parts[:-1]))


def code_of(line):
    """The line without strings, character literals and comments (for counting braces)."""
    s = re.sub(r'"(\\.|[^"\\])*"', '""', line)
    s = re.sub(r"'(\\.|[^'\\])'", "", s)
    return s.split("//")[0]


def block_end(lines, start):
    """The index of the line closing the block opened at or after `start` (None: a
    declaration without a body)."""
    depth, opened = 0, False
    for k in range(start, len(lines)):
        s = code_of(lines[k])
        depth += s.count("{") - s.count("}")
        opened = opened or "{" in s
        if opened and depth <= 0:
            return k
        if not opened and lines[k].rstrip().endswith(";"):
            return None
    return len(lines) - 1


def long_functions(path, lines):
    out, i = [], 0
    while i < len(lines):
        if re.match(r"\s*#\[cfg\(test\)\]", lines[i]) and i + 1 < len(lines) \
                and re.match(r"\s*(pub\s+)?mod\s+\w+\s*\{", lines[i + 1]):
            end = block_end(lines, i + 1)
            i = (end if end is not None else i) + 1
            continue
        m = FN.match(lines[i])
        if m:
            end = block_end(lines, i)
            if end is not None and end - i + 1 > MAX_FN_LINES:
                out.append(f"{path}:{i + 1}: fn `{m.group(6)}` is {end - i + 1} lines "
                           f"(at most {MAX_FN_LINES} outside tests): split it by what it does")
        i += 1
    return out


def main():
    root = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..")
    files = subprocess.run(["git", "ls-files", "*.rs"], cwd=root, capture_output=True,
                           text=True, check=True).stdout.split()
    bad = []
    for f in sorted(files):
        if not is_checked(f):
            continue
        with open(os.path.join(root, f), encoding="utf-8") as fh:
            lines = fh.read().split("\n")
        n = len(lines) - (1 if lines and lines[-1] == "" else 0)
        if n > MAX_FILE_LINES:
            bad.append(f"{f}: {n} lines (at most {MAX_FILE_LINES}): split it by concept")
        bad += long_functions(f, lines)
    for line in bad:
        print(line)
    if bad:
        sys.exit(1)
    n = sum(1 for f in files if is_checked(f))
    print(f"sizes: {n} Rust source files, none over {MAX_FILE_LINES} lines outside tests, "
          f"no function over {MAX_FN_LINES} lines outside tests")


if __name__ == "__main__":
    main()

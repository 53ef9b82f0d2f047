#!/usr/bin/env python3
"""The mutation check (issue 40, docs/testing.md): break the code on purpose, one way at a time,
and show that a test of the README's command catches each break.

Each mutation replaces an exact piece of a source file (the script fails if the piece is not
there the expected number of times, so it cannot go stale silently), runs the tests named for
it, restores the file byte for byte, and counts the mutation as *caught* when the tests fail.
The run ends with a table and exits non-zero if any mutation was missed.

    python3 scripts/mutations.py            # every mutation (about 20 min on 2 cores)
    python3 scripts/mutations.py --list     # what each one breaks and which test catches it
    python3 scripts/mutations.py --check    # every mutation still applies (./scripts/test.sh)
    python3 scripts/mutations.py two-port-halves release-at-rest

Builds in release into the usual target folder (`CARGO_TARGET_DIR` if set), so the mutated crate
and its dependents are rebuilt, then rebuilt again by the next normal build. Logs go to
`<target>/mutations/<name>.log`. Interrupting the script restores the file.
"""

from __future__ import annotations

import argparse
import os
import pathlib
import signal
import subprocess
import sys
import time
from dataclasses import dataclass

ROOT = pathlib.Path(__file__).resolve().parent.parent


@dataclass(frozen=True)
class Mutation:
    name: str
    what: str
    path: str
    old: str
    new: str
    count: int
    # Each command is a cargo test invocation (arguments after `cargo test --release`); the
    # mutation is caught when at least one of them fails.
    tests: tuple[tuple[str, ...], ...]


MUTATIONS = (
    Mutation(
        name="release-at-rest",
        what="the released brick leaves the hand at rest (no throw, no carried velocity)",
        path="crates/brickworld/src/hand/release.rs",
        old="rb.set_linvel(v, true);",
        new="rb.set_linvel(Vector::ZERO, true);",
        count=2,
        tests=(("-p", "brickworld", "--test", "carry"), ("-p", "brickworld", "--test", "coupling")),
    ),
    Mutation(
        name="synthesis-skips-a-sound",
        what="the page's live sound synthesis skips the first sound it is sent (the offline path plays it)",
        path="crates/play/src/page/synth.js",
        old="const tS = st * this.dt, index = dv.getUint32(at + 8, true);",
        new="if (!this.offline && !this.skipped) { this.skipped = true; continue; }\n        const tS = st * this.dt, index = dv.getUint32(at + 8, true);",
        count=1,
        tests=(("-p", "nanohaptics-play", "--test", "browser_sound"),),
    ),
    Mutation(
        name="guess-taken-unchecked",
        what="the page's sound takes every sample it played as a guess as the track's, unchecked against the ticks that came",
        path="crates/play/src/page/synth.js",
        old="if (!dev && played === f) {",
        new="if (true) {",
        count=1,
        tests=(("-p", "nanohaptics-play", "--test", "browser_sound"),),
    ),
    Mutation(
        name="skip-unheard",
        what="the page's sound skips the queued samples to follow the lead whether or not they are silent",
        path="crates/play/src/page/synth.js",
        old="while (z < limit && fifo.buf[fifo.head + z] === 0) z++;",
        new="while (z < limit) z++;",
        count=1,
        tests=(("-p", "nanohaptics-play", "--test", "browser_sound"),),
    ),
    Mutation(
        name="welcome-at-1khz",
        what="the bridge welcomes every scene at 1 kHz (a 10 kHz scene's device sends 1000 samples/s)",
        path="crates/devices/src/bridge/udp.rs",
        old="self.rate_hz = rate_hz;",
        new="self.rate_hz = 1000;",
        count=1,
        tests=(
            (
                "-p",
                "haptic-loop",
                "--test",
                "bridge",
                "the_welcome_carries_the_scenes_rate_name_and_start_time",
            ),
        ),
    ),
    Mutation(
        name="solver-ignored",
        what="the brick world ignores the solver iterations the scene sets (always 4, the default)",
        path="crates/brickworld/src/bricks.rs",
        old="phys.integration_parameters.num_solver_iterations = params.solver_iterations;",
        new="phys.integration_parameters.num_solver_iterations = 4;",
        count=1,
        tests=(("-p", "haptic-loop", "--test", "record_replay"),),
    ),
    Mutation(
        name="two-port-halves",
        what="the device side's two-port layer halves every force it renders",
        path="crates/devices/src/local.rs",
        old="f = self.bound(f, v, servo_s);",
        new="f = vec3::scale(self.bound(f, v, servo_s), 0.5);",
        count=1,
        tests=(("-p", "haptic-loop", "--test", "link"),),
    ),
    Mutation(
        name="observer-skips-late-samples",
        what="the passivity observer skips a sample that came a tick late (the world's energy then "
        "charges the skipped steps at once, at the force of the next on-time one)",
        path="crates/engine/src/haptic/input.rs",
        old="        if !valid {\n            return None;\n        }",
        new="        if !valid || sample.age_ticks > 0 {\n            return None;\n        }",
        count=1,
        tests=(
            (
                "-p",
                "haptic-loop",
                "--test",
                "loop_guarantees",
                "the_observer_counts_the_work_of_late_samples_as_of_on_time_ones",
            ),
        ),
    ),
    Mutation(
        name="bond-never-breaks",
        what="protocol 3's bond never breaks (the device pulls past the pull-off, as protocol 2 did)",
        path="crates/types/src/local/bond.rs",
        old="self.stretch_m(p) < self.break_m",
        new="self.stretch_m(p) < f64::INFINITY",
        count=1,
        tests=(
            (
                "-p",
                "haptic-loop",
                "--test",
                "link",
                "the_atoms_pull_off_behind_10_ms_overshoots_with_protocol_2_and_not_with_protocol_3",
            ),
            ("-p", "haptic-devices", "--test", "device_side_fixture"),
        ),
    ),
    Mutation(
        name="follower-never-steps",
        what="protocol 4's follower is never stepped by the device (its particle stays where the answer put it)",
        path="crates/devices/src/local.rs",
        old="                f.step(p);",
        new="                let _ = (&f, p);",
        count=1,
        tests=(
            ("-p", "haptic-devices", "--test", "follower"),
            (
                "-p",
                "haptic-loop",
                "--test",
                "link",
                "the_10_khz_trap_drags_behind_10_ms_with_protocol_3_and_not_with_protocol_4",
            ),
        ),
    ),
    Mutation(
        name="edge-planes-sent",
        what="the brick world sends a neighbour's edge seen across a gap as a plane for the carried body, at the angle it is seen from",
        path="crates/brickworld/src/hand/carry.rs",
        old="if c.dist <= 0.0 || faces(n, &pose) || faces(n, co.position()) {",
        new="if c.dist.is_finite() || faces(n, &pose) || faces(n, co.position()) {",
        count=1,
        tests=(
            ("-p", "brickworld", "--test", "local_planes"),
            (
                "-p",
                "haptic-loop",
                "--test",
                "link",
                "every_scene_on_every_device_is_stable_and_transparent_behind_a_link_of_up_to_10_ms",
            ),
        ),
    ),
)


def target_dir() -> pathlib.Path:
    t = os.environ.get("CARGO_TARGET_DIR")
    return pathlib.Path(t) if t else ROOT / "target"


def anchored(m: Mutation) -> str:
    """The text of `m`'s file; exits naming the mutation when its piece is not there as often
    as expected (the code moved: the mutation must be updated, not skipped)."""
    text = (ROOT / m.path).read_text()
    found = text.count(m.old)
    if found != m.count:
        raise SystemExit(
            f"mutation `{m.name}`: `{m.old}` occurs {found} times in {m.path}, expected {m.count}"
            " (the code moved: update scripts/mutations.py)"
        )
    return text


def run_one(m: Mutation, logs: pathlib.Path) -> tuple[str, str]:
    """Applies `m`, runs its tests, restores the file. Returns (verdict, detail)."""
    path = ROOT / m.path
    original = path.read_bytes()
    text = anchored(m)
    log = logs / f"{m.name}.log"
    restore = lambda *_: path.write_bytes(original)  # noqa: E731
    old_int = signal.signal(signal.SIGINT, lambda *_: (restore(), sys.exit(130)))
    old_term = signal.signal(signal.SIGTERM, lambda *_: (restore(), sys.exit(143)))
    try:
        path.write_text(text.replace(m.old, m.new))
        failed = []
        with log.open("w") as out:
            for t in m.tests:
                cmd = ["cargo", "test", "--release", *t]
                out.write(f"$ {' '.join(cmd)}\n")
                out.flush()
                r = subprocess.run(cmd, cwd=ROOT, stdout=out, stderr=subprocess.STDOUT)
                if r.returncode != 0:
                    failed.append(" ".join(t))
        if "error: could not compile" in log.read_text(errors="replace"):
            return "NOT BUILT", f"the mutated code did not compile (see {log})"
        if failed:
            return "caught", "; ".join(failed)
        return "MISSED", "all of its tests passed"
    finally:
        restore()
        signal.signal(signal.SIGINT, old_int)
        signal.signal(signal.SIGTERM, old_term)


def failing_tests(log: pathlib.Path) -> list[str]:
    """The names of the tests the log reports as failed (cargo's `---- name stdout ----`)."""
    names = []
    for line in log.read_text(errors="replace").splitlines():
        if line.startswith("---- ") and line.endswith(" stdout ----"):
            names.append(line[5 : -len(" stdout ----")])
    return names


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("names", nargs="*", help="mutations to run (all when none)")
    ap.add_argument("--list", action="store_true", help="list the mutations and exit")
    ap.add_argument(
        "--check",
        action="store_true",
        help="only check that every mutation's piece of source is where it expects (no build)",
    )
    a = ap.parse_args()
    known = {m.name: m for m in MUTATIONS}
    if a.check:
        for m in MUTATIONS:
            anchored(m)
        print(f"all {len(MUTATIONS)} mutations apply to today's source")
        return 0
    if a.list:
        for m in MUTATIONS:
            tests = " | ".join(" ".join(t) for t in m.tests)
            print(f"{m.name}: {m.what}\n    {m.path}\n    caught by: cargo test --release {tests}")
        return 0
    unknown = [n for n in a.names if n not in known]
    if unknown:
        print(
            f"unknown mutation(s): {', '.join(unknown)}; known: {', '.join(known)}",
            file=sys.stderr,
        )
        return 2
    chosen = [known[n] for n in a.names] if a.names else list(MUTATIONS)
    logs = target_dir() / "mutations"
    logs.mkdir(parents=True, exist_ok=True)
    rows = []
    for m in chosen:
        t0 = time.monotonic()
        print(f"==> {m.name}: {m.what}", flush=True)
        verdict, detail = run_one(m, logs)
        names = failing_tests(logs / f"{m.name}.log") if verdict == "caught" else []
        dt = time.monotonic() - t0
        print(f"    {verdict} in {dt:.0f} s: {detail}", flush=True)
        for n in names:
            print(f"      failed: {n}", flush=True)
        rows.append((m.name, verdict))
    print("\nmutation                   verdict")
    for n, v in rows:
        print(f"{n:<26} {v}")
    missed = [n for n, v in rows if v != "caught"]
    if missed:
        print(f"\n{len(missed)} mutation(s) missed: {', '.join(missed)}", file=sys.stderr)
        return 1
    print(f"\nall {len(rows)} mutations caught (logs in {logs})")
    return 0


if __name__ == "__main__":
    sys.exit(main())

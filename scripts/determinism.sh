#!/usr/bin/env bash
# Determinism across CPU code paths and builds (docs/determinism.md), a CI step of .ci/run:
#   1. every golden recording replays bit for bit with glibc's FMA, AVX2 and AVX-512 code paths
#      switched off (GLIBC_TUNABLES: libm's exp, log, sin, pow ... take their SSE2 variants);
#   2. a build for baseline x86-64 and one for this CPU (-C target-cpu=native) each replay
#      every golden bit for bit;
#   3. each of the two builds records the same batch sessions and the other verifies them.
# About 10 minutes on 2 cores (two extra release builds of the program). Exit status 1 on any
# divergence.
set -euo pipefail
cd "$(dirname "$0")/.."

step() { printf '\n==> %s\n' "$*"; }
OFF="glibc.cpu.hwcaps=-AVX2,-FMA,-AVX512F"
GOLDENS=(recordings/*.mcap)
SCENES=(wall brickworld nanoworld optical_tweezers)

verify_all() { # $1: program, $2...: extra environment
  local prog=$1
  shift
  for g in "${GOLDENS[@]}"; do
    if ! env "$@" "$prog" replay --verify "$g" > /dev/null; then
      echo "DIVERGED: $prog replay --verify $g (env: $*)" >&2
      exit 1
    fi
    echo "  bit for bit: $g"
  done
}

step "glibc code paths: what the loader makes active (x86-64-v3 and v4 off with $OFF)"
/lib64/ld-linux-x86-64.so.2 --list-diagnostics 2>/dev/null | grep '^dl_hwcaps_subdirs' || true
GLIBC_TUNABLES=$OFF /lib64/ld-linux-x86-64.so.2 --list-diagnostics 2>/dev/null \
  | grep '^dl_hwcaps_subdirs_active' || true

step "the default build, glibc's FMA/AVX2/AVX-512 paths on, then off"
cargo build --release -q -p nanohaptics-cli --bin nanohaptics
verify_all target/release/nanohaptics
verify_all target/release/nanohaptics GLIBC_TUNABLES=$OFF

step "a build for baseline x86-64 and one for this CPU (target-cpu=native)"
RUSTFLAGS="-C target-cpu=x86-64" cargo build --release -q -p nanohaptics-cli --bin nanohaptics \
  --target-dir target/det-baseline
RUSTFLAGS="-C target-cpu=native" cargo build --release -q -p nanohaptics-cli --bin nanohaptics \
  --target-dir target/det-native
BASE=target/det-baseline/release/nanohaptics
NATIVE=target/det-native/release/nanohaptics
verify_all "$BASE"
verify_all "$NATIVE"
verify_all "$BASE" GLIBC_TUNABLES=$OFF

step "each build records, the other verifies"
out=target/det-cross
rm -rf "$out" && mkdir -p "$out"
for s in "${SCENES[@]}"; do
  "$NATIVE" run "$s" --seconds 2 --out "$out/$s-native.mcap" --json > /dev/null
  "$BASE" run "$s" --seconds 2 --out "$out/$s-baseline.mcap" --json > /dev/null
  GLIBC_TUNABLES=$OFF "$BASE" replay --verify "$out/$s-native.mcap" > /dev/null
  "$NATIVE" replay --verify "$out/$s-baseline.mcap" > /dev/null
  echo "  $s: native recording verified by the baseline build (glibc paths off), and back"
done
step "determinism holds across these builds and code paths"

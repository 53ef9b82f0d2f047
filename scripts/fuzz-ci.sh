#!/usr/bin/env bash
# The libFuzzer targets (fuzz/, cargo-fuzz on stable Rust with --sanitizer none), each for a
# bounded time from the committed corpus: a CI step of .ci/run (docs/fuzzing.md).
#   FUZZ_SECONDS   seconds per target (default 30)
#   FUZZ_TARGETS   targets to run (default: all of fuzz/fuzz_targets)
# The committed corpus is copied, never grown, by a CI run. Exit status 1 on a finding (a
# panic, a property assertion, an input slower than 10 minutes); its input is in
# fuzz/artifacts/<target>/ with the command that replays it.
set -euo pipefail
cd "$(dirname "$0")/.."
secs=${FUZZ_SECONDS:-30}
targets=${FUZZ_TARGETS:-"scene script recording verify bridge params page"}

if ! command -v cargo-fuzz > /dev/null; then
  echo "==> installing cargo-fuzz"
  cargo install cargo-fuzz --locked --version 0.13.2
fi
echo "==> building the libFuzzer targets (instrumented, fuzz/target)"
(cd fuzz && cargo fuzz build --sanitizer none -O)
work=fuzz/target/ci-corpus
rm -rf "$work"
status=0
for t in $targets; do
  mkdir -p "$work/$t"
  cp fuzz/corpus/"$t"/* "$work/$t/"
  log="fuzz/target/ci-$t.log"
  echo "==> $t: $secs s"
  if (cd fuzz && cargo fuzz run --sanitizer none -O "$t" "target/ci-corpus/$t" -- \
      -max_total_time="$secs" -timeout=600 -max_len=65536 -seed=1 -print_final_stats=1 \
      > "target/ci-$t.log" 2>&1); then
    grep -E '^#[0-9]+.*DONE' "$log" | tail -1 || true
    # Inputs slower than 10 s are findings too (reported, not fatal): docs/fuzzing.md.
    grep -E 'Slowest unit|slow-unit' "$log" | tail -2 || true
  else
    status=1
    echo "FINDING in $t:" >&2
    grep -E 'panicked|finding|Test unit written|ERROR|SUMMARY' "$log" | head -20 >&2
    echo "replay: (cd fuzz && cargo fuzz run --sanitizer none -O $t artifacts/$t/<file>)" >&2
  fi
done
exit $status

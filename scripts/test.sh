#!/usr/bin/env bash
# Runs every test of nanohaptics on a fresh machine:
#   formatting, the layering check, clippy, the Rust workspace tests, then the Python wheel
#   built by maturin into a fresh virtual environment and tested with pytest.
set -euo pipefail
cd "$(dirname "$0")/.."

step() { printf '\n==> %s\n' "$*"; }

# The tracked tree before the run: each path `git status` lists, with a hash of its content, so
# the run's own changes are told from edits the developer had already made (docs/testing.md).
tree_state() {
  git status --porcelain --untracked-files=all | while IFS= read -r line; do
    p=${line:3}
    p=${p##* -> }
    if [ -f "$p" ]; then h=$(git hash-object -- "$p"); else h=-; fi
    printf '%s %s\n' "$line" "$h"
  done
}
in_git=0
if git rev-parse --is-inside-work-tree >/dev/null 2>&1; then
  in_git=1
  tree_before=$(tree_state)
fi

step "cargo fmt --check"
cargo fmt --all -- --check

step "layering: crate dependencies one way, no import circles, no upward imports"
python3 scripts/layering.py

step "sizes: no source file over 700 lines, no function over 100 lines outside tests"
python3 scripts/sizes.py

step "the mutation check still applies to today's source (docs/testing.md)"
python3 scripts/mutations.py --check

step "cargo clippy (warnings are errors)"
cargo clippy --workspace --all-targets --release -- -D warnings

step "chromium for the browser tests (crates/play/tests/browser.rs)"
if ! command -v chromium >/dev/null; then
  sudo_=""; [ "$(id -u)" = 0 ] || sudo_="sudo"
  $sudo_ env DEBIAN_FRONTEND=noninteractive apt-get update -q &&
    $sudo_ env DEBIAN_FRONTEND=noninteractive apt-get install -y -q chromium
fi

step "cargo test (release profile)"
cargo test --workspace --release

step "fuzz: every target of the in-tree driver, a fixed input set each (about 20 s; libFuzzer runs in .ci/run, docs/fuzzing.md)"
cargo build --release -q -p nanohaptics-cli --bin nanohaptics
cargo run --release -q -p nanohaptics-fuzz -- --ci

if [ -d crates/ot-py ]; then
  step "Python wheel in a fresh virtual environment"
  rm -rf .venv
  python3 -m venv .venv
  .venv/bin/pip install --quiet --upgrade pip
  # maturin >= 1.9.4 sets PYO3_BUILD_EXTENSION_MODULE (pyo3 0.30 has no
  # extension-module feature): the wheel then does not link libpython.
  # pandas and dask[distributed]: the sweep tests (a 2-worker Dask process cluster) and the
  # docs' sweep examples (the extras `nanohaptics[sweep]` / `[dask]`). mcap,
  # mcap-ros2-support and mcap-protobuf-support: the golden recordings read by the MCAP
  # project's own decoders (test_recording_readers.py) and docs/recording-format.md's example
  # (a test or doc example whose module is missing fails, docs/testing.md).
  .venv/bin/pip install --quiet "maturin>=1.9.4,<2" "pytest>=8" "numpy>=1.26" "pandas>=1.5" \
    "dask[distributed]>=2023.1" "mcap>=1.2" "mcap-ros2-support>=0.5" "mcap-protobuf-support>=0.5"
  rm -rf target/wheels-test
  # pyproject.toml (at the workspace root) names crates/ot-py; the wheel is abi3 (CPython >= 3.9).
  .venv/bin/maturin build --release --out target/wheels-test --interpreter .venv/bin/python
  .venv/bin/pip install --quiet --force-reinstall --no-deps target/wheels-test/nanohaptics-*-abi3-*.whl
  if [ "${NANOHAPTICS_SDIST_INSTALL:-0}" = 1 ]; then
    # The full check (a from-scratch release build of the workspace, many minutes): build the
    # sdist and pip-install it into a second fresh environment, then import it.
    step "sdist: build and pip install"
    rm -rf target/sdist-test target/venv-sdist
    .venv/bin/maturin sdist --out target/sdist-test
    python3 -m venv target/venv-sdist
    target/venv-sdist/bin/pip install --quiet target/sdist-test/nanohaptics-*.tar.gz
    target/venv-sdist/bin/python -c "import nanohaptics as nh; print('sdist install:', nh.__version__, nh.__file__)"
  fi
  step "pytest (includes the docs examples and the sdist contents check)"
  # -rs: every skipped test with its reason (NANOHAPTICS_SKIP_REALTIME, docs/testing.md).
  .venv/bin/python -m pytest -q -rs tests/python
fi
step "the tracked tree: nothing changed by this run (tests write under target/)"
if [ "$in_git" = 1 ]; then
  tree_after=$(tree_state)
  if [ "$tree_before" != "$tree_after" ]; then
    echo "the run changed these paths (git status --porcelain, then a hash of the content):" >&2
    diff <(printf '%s\n' "$tree_before") <(printf '%s\n' "$tree_after") | grep '^[<>]' >&2 || true
    exit 1
  fi
  echo "unchanged"
else
  echo "not a git work tree: not checked"
fi
step "all tests passed"

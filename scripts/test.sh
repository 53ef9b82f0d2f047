#!/usr/bin/env bash
# Runs every test of nanohaptics on a fresh machine:
#   formatting, clippy, the Rust workspace tests, then the Python wheel
#   built by maturin into a fresh virtual environment and tested with pytest.
set -euo pipefail
cd "$(dirname "$0")/.."

step() { printf '\n==> %s\n' "$*"; }

step "cargo fmt --check"
cargo fmt --all -- --check

step "cargo clippy (warnings are errors)"
cargo clippy --workspace --all-targets --release -- -D warnings

step "cargo test (release profile)"
cargo test --workspace --release

if [ -d crates/ot-py ]; then
  step "Python wheel in a fresh virtual environment"
  rm -rf .venv
  python3 -m venv .venv
  .venv/bin/pip install --quiet --upgrade pip
  # maturin >= 1.9.4 sets PYO3_BUILD_EXTENSION_MODULE (pyo3 0.30 has no
  # extension-module feature): the wheel then does not link libpython.
  .venv/bin/pip install --quiet "maturin>=1.9.4,<2" "pytest>=8" "numpy>=1.26"
  rm -rf target/wheels-test
  .venv/bin/maturin build --release --manifest-path crates/ot-py/Cargo.toml --out target/wheels-test --interpreter .venv/bin/python
  .venv/bin/pip install --quiet --force-reinstall --no-deps target/wheels-test/nanohaptics-*.whl
  step "pytest"
  .venv/bin/python -m pytest -q tests/python
fi
step "all tests passed"

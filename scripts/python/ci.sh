#!/usr/bin/env bash
# The Python package (python/, PyO3 + maturin; a workspace member, not a default one): rustfmt
# and clippy of its crate, then a fresh venv, the package built into it by
# `pip install ./python` (maturin, sharing target/ with the workspace's release build), and its
# pytest suite, which compares it with the `magsep` CLI (built here if missing).
#
# Usage: scripts/python/ci.sh            (from anywhere; .ci/run calls it)
# Environment: MAGSEP_PY_VENV=DIR        reuse or create the venv at DIR (default: a temp dir)
set -euo pipefail
cd "$(dirname "$0")/../.."
root="$PWD"
export CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$root/target}"
start=$SECONDS

echo "== python: cargo fmt --check and clippy -D warnings of python/"
cargo fmt --manifest-path python/Cargo.toml -- --check
PYO3_PYTHON="$(command -v python3)" cargo clippy --release --quiet --manifest-path python/Cargo.toml \
  --all-targets -- -D warnings

echo "== python: venv, pip install ./python, pytest"
venv="${MAGSEP_PY_VENV:-$(mktemp -d)/venv}"
[ -x "$venv/bin/python" ] || python3 -m venv "$venv"
export PATH="$venv/bin:$PATH"
# maturin, numpy and pytest from PyPI; pandas for to_pandas()
python -m pip install --quiet --disable-pip-version-check maturin numpy pytest pandas
# --no-build-isolation: use the maturin just installed instead of a second download
python -m pip install --quiet --disable-pip-version-check --no-build-isolation ./python
cargo build --release --quiet --bin magsep
MAGSEP_BIN="$CARGO_TARGET_DIR/release/magsep" python -m pytest -q python/tests
echo "python stage: $((SECONDS - start)) s"

#!/usr/bin/env bash
# Eigensolver benchmark against scipy (docs/decisions.md, "Eigensolver"). Builds shapecorr, makes a virtual
# environment with numpy and scipy, and runs tests/bench/eigen_vs_scipy.py.
# Usage: tests/bench/eigen.sh [--data DIR] [--repeat N]
set -euo pipefail
cd "$(dirname "$0")/../.."
cargo build --release --quiet
venv=target/bench-venv
if [ ! -x "$venv/bin/python" ]; then
  python3 -m venv "$venv"
  "$venv/bin/pip" install --quiet numpy scipy
fi
exec "$venv/bin/python" tests/bench/eigen_vs_scipy.py "$@"

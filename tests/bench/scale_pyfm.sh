#!/usr/bin/env bash
# `shapecorr bench scale` with pyFM as the reference: makes the pinned pyFM venv of
# p2p_vs_pyfm.sh (target/pyfm-venv) if missing, builds the release binary and runs
#
#   target/release/shapecorr bench scale --pyfm-python target/pyfm-venv/bin/python "$@"
#
# with every BLAS/OpenMP pool of pyFM on one thread (as p2p_vs_pyfm.sh does).
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
VENV="$ROOT/target/pyfm-venv"
PY="${PYTHON:-python3}"
# The pins of p2p_vs_pyfm.sh, read from it so the two never differ.
mapfile -t PINS < <(sed -n '/^PINS=(/,/^)/p' "$ROOT/tests/bench/p2p_vs_pyfm.sh" | grep -v '^PINS=(\|^)' | tr -d ' ')
mkdir -p "$ROOT/target"
if [ ! -x "$VENV/bin/python" ]; then
  "$PY" -m venv "$VENV"
fi
STAMP="$VENV/.p2p_vs_pyfm-pins"
if [ "$(cat "$STAMP" 2>/dev/null || true)" != "${PINS[*]}" ]; then
  "$VENV/bin/python" -m pip install --quiet --disable-pip-version-check "${PINS[@]}"
  echo "${PINS[*]}" > "$STAMP"
fi
(cd "$ROOT" && cargo build --release --locked)
export OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 MKL_NUM_THREADS=1
cd "$ROOT"
exec target/release/shapecorr bench scale --pyfm-python "$VENV/bin/python" "$@"

#!/usr/bin/env bash
# Point-to-point maps, shapecorr vs pyFM (pyfmaps: WKS functional map + ZoomOut, its README
# recipe), on the same shape pairs, timed in one script, scored by `shapecorr bench maps`.
#
#   tests/bench/p2p_vs_pyfm.sh --data ../shared/data --pairs ../shared/data/pairs/faust.txt \
#       [--limit N] [--out DIR] [--pyfm-self-error] [--skip-pyfm] [--skip-ours]
#
# Makes target/pyfm-venv (pinned pyfmaps and its dependencies) if missing or if the pins
# changed, builds the release binary, then runs tests/bench/p2p_vs_pyfm.py with every
# BLAS/OpenMP pool on one thread. Outputs go to --out (default target/p2p_vs_pyfm); the
# benchmark shapes are research-only and are only read, never copied.
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
VENV="$ROOT/target/pyfm-venv"
PY="${PYTHON:-python3}"

# Exact versions that install and run together here (Python 3.11, Linux x86_64):
# pyfmaps and everything it pulls in (numpy, scipy, scikit-learn, potpourri3d,
# robust_laplacian, tqdm) plus the transitive ones (joblib, threadpoolctl, narwhals,
# cloudpickle).
PINS=(
  pyfmaps==1.3.1
  numpy==2.4.6
  scipy==1.17.1
  scikit-learn==1.9.1
  potpourri3d==1.4.0
  robust_laplacian==1.1.0
  tqdm==4.70.1
  joblib==1.6.0
  threadpoolctl==3.8.0
  narwhals==2.29.0
  cloudpickle==3.1.3
)

if [ "$#" -eq 0 ]; then
  sed -n '2,11p' "$0" | sed 's/^# \{0,1\}//'
  exit 2
fi

mkdir -p "$ROOT/target"
if [ ! -x "$VENV/bin/python" ]; then
  echo "== creating $VENV"
  "$PY" -m venv "$VENV"
fi
STAMP="$VENV/.p2p_vs_pyfm-pins"
if [ "$(cat "$STAMP" 2>/dev/null || true)" != "${PINS[*]}" ]; then
  echo "== installing ${PINS[*]}"
  "$VENV/bin/python" -m pip install --quiet --disable-pip-version-check "${PINS[@]}"
  echo "${PINS[*]}" > "$STAMP"
fi

echo "== cargo build --release --locked"
if ! (cd "$ROOT" && cargo build --release --locked); then
  echo "WARNING: cargo build failed; the run goes on with whatever target/release/shapecorr" \
       "is there (possibly stale or missing: our side and the evaluation are then skipped)" >&2
fi

export OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 MKL_NUM_THREADS=1
echo "== one BLAS thread: OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 MKL_NUM_THREADS=1"
exec "$VENV/bin/python" "$ROOT/tests/bench/p2p_vs_pyfm.py" "$@"

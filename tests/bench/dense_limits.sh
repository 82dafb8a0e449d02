#!/usr/bin/env bash
# The limits of a job on a dense pair (docs/decisions.md, "Dense shapes: limits"): two
# 1.9M-vertex figures (120K-vertex `synth` figures subdivided twice), then
# 1. ceilings and time limits the estimate refuses before reading (time and peak RSS);
# 2. a time limit above the estimate: how long after it the job stops;
# 3. a memory ceiling the estimate accepts: the peak RSS against it;
# 4. cancel latency per stage (reading, repair, proxy, eigenbasis, matching).
# Usage: tests/bench/dense_limits.sh [WORK_DIR]   (needs the release build with examples:
# cargo build --release --workspace --all-targets)
set -uo pipefail
cd "$(dirname "$0")/../.."
S=target/release/shapecorr; X=target/release/examples; W=${1:-/tmp/shapecorr_dense}
mkdir -p "$W"; export RAYON_NUM_THREADS=${RAYON_NUM_THREADS:-1}
if [ ! -f "$W/big3.ply" ]; then
  $S synth --vertices 120000 --out "$W/s0.ply" --quiet
  $S synth --vertices 120000 --pose 3 --out "$W/s3.ply" --quiet
  $X/subdivide "$W/s0.ply" "$W/big.ply" 2; $X/subdivide "$W/s3.ply" "$W/big3.ply" 2
fi
peak() { /usr/bin/time -f "  wall %e s, peak RSS %M KB, exit %x" "$@" --quiet 2>&1 | tail -2; }
echo "== refused before reading"
for o in "--memory-limit-mib 200" "--memory-limit-mib 400" "--time-limit-s 3"; do
  echo "match $o"; peak $S match "$W/big.ply" "$W/big3.ply" --out "$W/o" $o
done
echo "== time limit above the estimate (${LIMIT:-30} s): stops how long after it"
peak $S match "$W/big.ply" "$W/big3.ply" --out "$W/o" --time-limit-s ${LIMIT:-30}
echo "== memory ceiling ${CEILING:-1100} MiB (accepted): peak against it"
peak $S match "$W/big.ply" "$W/big3.ply" --out "$W/o" --memory-limit-mib ${CEILING:-1100} --time-limit-s 0
echo "== cancel latency per stage"
$X/dense_limits "$W/big.ply" "$W/big3.ply" 0.3

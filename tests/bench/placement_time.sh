#!/usr/bin/env bash
# The default path (`--placement auto`) against the pipeline before placement (`--placement
# ignore`, which verifies no frame hypothesis), same FAUST_r pairs, alternating, the CLI's
# wall time per pair (docs/placement.md, "Time"). Needs ../shared/data (skips without it).
# Usage: tests/bench/placement_time.sh [--data DIR] [PAIRS]
set -euo pipefail
cd "$(dirname "$0")/../.."
data=../shared/data
if [ "${1:-}" = "--data" ]; then data=$2; shift 2; fi
pairs=${1:-8}
dir="$data/faust_r/off"
if [ ! -d "$dir" ]; then echo "no $dir: skipped"; exit 0; fi
cargo build --release --quiet -p shapecorr-cli
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
for ((i = 0; i < pairs; i++)); do
  a=$(printf "%s/tr_reg_%03d.off" "$dir" $((2 * i)))
  b=$(printf "%s/tr_reg_%03d.off" "$dir" $((2 * i + 1)))
  for mode in auto ignore; do
    start=$(date +%s.%N)
    target/release/shapecorr p2p "$a" "$b" --out "$out/$mode" --quiet --placement "$mode" > /dev/null
    end=$(date +%s.%N)
    echo "$mode $(basename "$a") $(basename "$b") $(echo "$end - $start" | bc)"
  done
done | awk '{print; s[$1] += $4; n[$1]++}
  END {printf "mean: auto %.3f s, ignore %.3f s, ratio %.2f\n", s["auto"]/n["auto"], s["ignore"]/n["ignore"], (s["auto"]/n["auto"])/(s["ignore"]/n["ignore"])}'

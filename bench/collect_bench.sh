#!/usr/bin/env bash
# Benchmark (not a test): time to record the paper preset with all cores,
# against the same preset on one job as the baseline, in the same run, and
# the plant's physics steps per second. Prints the machine it ran on.
# Usage: bench/collect_bench.sh [BUILD_DIR]   (default build/release)
set -euo pipefail
cd "$(dirname "$0")/.."
build="${1:-build/release}"
hadynet="$build/cli/hadynet"
[[ -x "$hadynet" ]] || { echo "build first: scripts/build.sh release" >&2; exit 1; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs)"
run() {  # run JOBS -> prints the collect summary line, sets $seconds
  local jobs=$1 start end
  start=$(date +%s.%N)
  "$hadynet" collect --preset paper --seed 1 --jobs "$jobs" --quiet --out "$work/j$jobs" >"$work/out$jobs"
  end=$(date +%s.%N)
  seconds=$(awk -v a="$start" -v b="$end" 'BEGIN { print b - a }')
  cat "$work/out$jobs"
}
run 1; base=$seconds
run "$(nproc)"; all=$seconds
printf 'paper preset: %.1f s with %d jobs, %.1f s with 1 job (baseline): speed-up %.2fx\n' \
  "$all" "$(nproc)" "$base" "$(awk -v a="$base" -v b="$all" 'BEGIN { print a / b }')"
cmp -s <(cd "$work/j1" && find . -type f -exec md5sum {} + | sort) \
       <(cd "$work/j$(nproc)" && find . -type f -exec md5sum {} + | sort) \
  && echo "outputs identical across job counts" || { echo "outputs differ across job counts" >&2; exit 1; }

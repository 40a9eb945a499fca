#!/usr/bin/env bash
# Benchmark (not a test): training on a machine it shares (issue 18, item 9).
# Median seconds per epoch of `hadynet train` on the paper preset, with all
# cores and with one thread, on an idle machine and with one core kept busy
# by another process (`yes > /dev/null`), all in this run on this machine.
# The baseline is the same binary with --threads 1 in the same condition:
# training with every thread should never be slower than with one, busy or
# not, and a busy core should cost about the share of the CPU it takes.
#
# Usage: bench/train_shared_core.sh [EPOCHS]   (default 5; DATA=dir for another
#        dataset folder)
set -euo pipefail
cd "$(dirname "$0")/.."
epochs="${1:-5}"
data="${DATA:-data/paper}"

scripts/build.sh release >/dev/null
hadynet=build/release/cli/hadynet
if [[ ! -f "$data/manifest.json" ]]; then
  "$hadynet" collect --preset paper --out "$data"
fi
work="$(mktemp -d)"
busy_pid=""
trap '[[ -n "$busy_pid" ]] && kill "$busy_pid" 2>/dev/null; rm -rf "$work"' EXIT

ratio() { awk -v a="$1" -v b="$2" 'BEGIN { print a / b }'; }
median() { sort -g | awk '{v[NR]=$1} END {print (NR%2 ? v[(NR+1)/2] : (v[NR/2]+v[NR/2+1])/2)}'; }
# epoch_seconds THREADS: median seconds per epoch (column 4 of MODEL.loss.csv)
epoch_seconds() {
  "$hadynet" train "$data/train" --out "$work/m.safetensors" --epochs "$epochs" --held-out 0 \
    --threads "$1" --quiet >/dev/null
  tail -n +2 "$work/m.safetensors.loss.csv" | cut -d, -f4 | median
}

echo "machine: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs), $(nproc) cores; $epochs epochs each"
idle_all=$(epoch_seconds 0)
idle_one=$(epoch_seconds 1)
yes > /dev/null &
busy_pid=$!
busy_all=$(epoch_seconds 0)
busy_one=$(epoch_seconds 1)
kill "$busy_pid"
busy_pid=""

printf '%-28s %10s %10s %16s\n' "" "all cores" "1 thread" "all / 1 thread"
printf '%-28s %10.3f %10.3f %16.2f\n' "idle machine (s/epoch)" "$idle_all" "$idle_one" "$(ratio "$idle_all" "$idle_one")"
printf '%-28s %10.3f %10.3f %16.2f\n' "one core busy (s/epoch)" "$busy_all" "$busy_one" "$(ratio "$busy_all" "$busy_one")"
printf 'a busy core costs %.2fx with all cores\n' "$(ratio "$busy_all" "$idle_all")"

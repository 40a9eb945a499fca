#!/usr/bin/env bash
# Benchmark (not a test): PB adaptation with every core against one thread.
# The four grasps of docs/residual.md recorded with seed SEED, ROWS rows
# each, through `hadynet recognize` (one PB adapted per log, offline) and
# `hadynet adapt --online` (the paper's streamed adaptation of one log),
# timed in wall seconds alone with --threads 1 (the baseline and the
# default, measured in this run) and --threads 0 (every core), one run per
# cell, 1 thread first. The results are the same bytes at any count
# (cli.pb_threads); this measures only the time (the work pool:
# docs/trainer.md, "Threads").
# Data roles: the model is trained on seed 1 (collect --preset paper); seed
# 1194 is recorded for this timing alone, and nothing is chosen on it.
#
# Usage: bench/pb_threads.sh [--seed S] [--rows N] [--model M]
#   defaults: 1194, 600, models/hand.safetensors
# Environment: HADYNET (default build/release/cli/hadynet).
set -euo pipefail
usage() { sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'; }
seed=1194
rows=600
model=models/hand.safetensors
while (($#)); do
  case "$1" in
    -h | --help) usage; exit 0 ;;
    --seed) seed=$2; shift 2 ;;
    --rows) rows=$2; shift 2 ;;
    --model) model=$2; shift 2 ;;
    *) echo "pb_threads: unknown argument $1" >&2; exit 2 ;;
  esac
done
cd "$(dirname "$0")/.."
source bench/residual_grasps.sh
hadynet="${HADYNET:-build/release/cli/hadynet}"
[[ -x "$hadynet" ]] || { echo "pb_threads: $hadynet not found" >&2; exit 2; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
RESIDUAL_ROWS=$rows collect_residual_grasps "$hadynet" "$work/logs" "$seed"
online_log=$(find "$work/logs" -name "Cylinder_random2_*.csv" | head -1)
now() { date +%s.%N; }
elapsed() { awk -v a="$1" -v b="$(now)" 'BEGIN { printf "%.1f", b - a }'; }
ratio() { awk -v a="$1" -v b="$2" 'BEGIN { printf "%.2f", a / b }'; }
# timed TAG COMMAND...: runs it (output in WORK/TAG.txt), prints its wall seconds; a failure ends the benchmark
timed() {
  local tag=$1 s
  shift
  s=$(now)
  "$@" >"$work/$tag.txt" 2>&1 || { echo "pb_threads: $tag failed:" >&2; tail -5 "$work/$tag.txt" >&2; return 1; }
  elapsed "$s"
}
echo "machine: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs), $(nproc) cores; seed $seed, $rows rows"
rec1=$(timed rec1 "$hadynet" recognize "$model" "$work/logs" --threads 1 --json "$work/rec1.json")
rec0=$(timed rec0 "$hadynet" recognize "$model" "$work/logs" --threads 0 --json "$work/rec0.json")
onl1=$(timed onl1 "$hadynet" adapt "$model" "$online_log" --online --threads 1 --csv "$work/onl1.csv")
onl0=$(timed onl0 "$hadynet" adapt "$model" "$online_log" --online --threads 0 --csv "$work/onl0.csv")
cmp -s "$work/rec1.json" "$work/rec0.json" || echo "note: recognize wrote different JSON at the two counts (a bug: cli.pb_threads)"
cmp -s "$work/onl1.csv" "$work/onl0.csv" || echo "note: adapt --online wrote different CSV at the two counts (a bug)"
printf '%-34s %10s %10s %8s\n' "" "1 thread" "every core" "every/1"
printf '%-34s %10s %10s %8s\n' "recognize, 4 logs (s)" "$rec1" "$rec0" "$(ratio "$rec0" "$rec1")"
printf '%-34s %10s %10s %8s\n' "adapt --online, 1 log (s)" "$onl1" "$onl0" "$(ratio "$onl0" "$onl1")"

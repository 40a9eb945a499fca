#!/usr/bin/env bash
# Benchmark (not a test): `hadynet residual --fix` with every core against
# one thread. One plant set (the four grasps of docs/residual.md, 300 rows,
# seed SEED with the plant's cross-talk, declared nowhere) through --fix with
# the plant's rated ranges, timed in wall seconds: alone with --threads 1
# (the baseline and the default, measured in this run) and --threads 0
# (every core), then two runs at once with each count, as `ctest -j2` runs
# two tests of the suite. The results are the same bytes at any count
# (cli.residual.threads); this measures only the time, one run per cell (1
# thread first). Every core should be faster alone, and cost little when
# another run holds a core (the work pool: docs/trainer.md, "Threads").
#
# Usage: bench/residual_threads.sh [--seed S] [--model M]
#   defaults: 4861 (a development set of the tie-break), models/hand-4seeds.safetensors
# Environment: HADYNET (default build/release/cli/hadynet).
set -euo pipefail
usage() { sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'; }
seed=4861
model=models/hand-4seeds.safetensors
while (($#)); do
  case "$1" in
    -h | --help) usage; exit 0 ;;
    --seed) seed=$2; shift 2 ;;
    --model) model=$2; shift 2 ;;
    *) echo "residual_threads: unknown argument $1" >&2; exit 2 ;;
  esac
done
cd "$(dirname "$0")/.."
source bench/residual_grasps.sh
hadynet="${HADYNET:-build/release/cli/hadynet}"
[[ -x "$hadynet" ]] || { echo "residual_threads: $hadynet not found" >&2; exit 2; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
collect_residual_grasps "$hadynet" "$work/logs" "$seed" --effect crosstalk=0.35
# fix THREADS TAG: one --fix run; its output in WORK/TAG.txt, a failure ends the benchmark
fix() {
  "$hadynet" residual "$model" "$work/logs" --rated-range fc=0..50 --rated-range f=0..200 --fix --threads "$1" \
    --json "$work/$2.json" >"$work/$2.txt" 2>&1 || { echo "residual_threads: --threads $1 failed:" >&2; tail -5 "$work/$2.txt" >&2; return 1; }
}
# pair THREADS: two --fix runs at once
pair() {
  local a b
  fix "$1" a"$1" & a=$!
  fix "$1" b"$1" & b=$!
  wait "$a" && wait "$b"
}
now() { date +%s.%N; }
elapsed() { awk -v a="$1" -v b="$(now)" 'BEGIN { printf "%.1f", b - a }'; }
echo "machine: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs), $(nproc) cores; seed $seed"
s=$(now); fix 1 alone1; alone1=$(elapsed "$s")
s=$(now); fix 0 alone0; alone0=$(elapsed "$s")
s=$(now); pair 1; pair1=$(elapsed "$s")
s=$(now); pair 0; pair0=$(elapsed "$s")
cmp -s "$work/alone1.json" "$work/alone0.json" || echo "note: the two counts wrote different JSON (a bug: cli.residual.threads)"
printf '%-28s %10s %10s %8s\n' "" "1 thread" "every core" "every/1"
printf '%-28s %10s %10s %8s\n' "alone (s)" "$alone1" "$alone0" "$(awk -v a="$alone0" -v b="$alone1" 'BEGIN { printf "%.2f", a / b }')"
printf '%-28s %10s %10s %8s\n' "two runs at once (s, both)" "$pair1" "$pair0" "$(awk -v a="$pair0" -v b="$pair1" 'BEGIN { printf "%.2f", a / b }')"

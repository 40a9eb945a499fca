#!/usr/bin/env bash
# Issue 12's detection bar with its cut read on the channels the plant's
# effect moved (bench/residual_footprint.py says how), over the sets of
# one or more bench/residual_detection.sh output directories (not a test).
#
#   bench/residual_footprint.sh --out DIR [--share X] BENCH_OUT...
#
# BENCH_OUT: a residual_detection.sh --out directory (CASE/seedS/ sets) or a
# directory of them (two halves run side by side: BENCH_OUT/A, BENCH_OUT/B).
# Records each seed's four grasps without an effect once (DIR/clean/seedS,
# bench/residual_grasps.sh, RESIDUAL_ROWS as the sets were recorded: 300
# unless set), writes a line per set to DIR/lines.txt and the table per case
# to DIR/summary.txt. Sets recorded under a re-zeroing
# (--rezeroed-first-init) are not supported: their clean twin would need
# the same zeroing.
# Environment: HADYNET (default build/release/cli/hadynet).
set -euo pipefail
usage() { sed -n '2,17p' "$0" | sed 's/^# \{0,1\}//'; }
out="" share=0.5 trees=()
while (($#)); do
  case "$1" in
    -h | --help) usage; exit 0 ;;
    --out) out=$2; shift 2 ;;
    --share) share=$2; shift 2 ;;
    -*) echo "residual_footprint: unknown option $1" >&2; exit 2 ;;
    *) trees+=("$(cd "$1" && pwd)"); shift ;;
  esac
done
[[ -n "$out" && ${#trees[@]} -gt 0 ]] || { usage >&2; exit 2; }
cd "$(dirname "$0")/.."
source bench/residual_grasps.sh
hadynet="${HADYNET:-build/release/cli/hadynet}"
[[ -x "$hadynet" ]] || { echo "residual_footprint: $hadynet not found" >&2; exit 2; }
mkdir -p "$out/clean"
lines="$out/lines.txt"
: >"$lines"
mapfile -t sets < <(find "${trees[@]}" -path '*/seed*/residual.json' -printf '%h\n' | sort)
((${#sets[@]})) || { echo "residual_footprint: no set under ${trees[*]}" >&2; exit 2; }
start=$(date +%s) k=0
for d in "${sets[@]}"; do
  seed=${d##*/seed} case=$(basename "$(dirname "$d")")
  clean="$out/clean/seed$seed"
  record_clean_twin "$hadynet" "$clean" "$seed" || { echo "residual_footprint: collect seed $seed failed" >&2; exit 1; }
  python3 bench/residual_footprint.py line "$case" "$seed" "$d" "$clean" --share "$share" | tee -a "$lines"
  k=$((k + 1))
  echo "[$k/${#sets[@]}, ETA $(( ($(date +%s) - start) * (${#sets[@]} - k) / k ))s]" >&2
done
python3 bench/residual_footprint.py table "$lines" | tee "$out/summary.txt"

#!/usr/bin/env bash
# Issue 12's detection bar beside the cut that fine-tuning reaches on each
# set's clean twin (bench/residual_twin_cut.py says how), over the sets of
# one or more bench/residual_detection.sh output directories (not a test).
#
#   bench/residual_twin_cut.sh --out DIR --model MODEL BENCH_OUT...
#
# BENCH_OUT: a residual_detection.sh --out directory (CASE/seedS/ sets) or a
# directory of them (two halves run side by side: BENCH_OUT/A, BENCH_OUT/B).
# MODEL: the model the sets were run with. Records each seed's four grasps
# without an effect once (DIR/clean/seedS, bench/residual_grasps.sh,
# RESIDUAL_ROWS as the sets were recorded: 300 unless set; a directory
# bench/residual_footprint.sh recorded with the same rows serves as it
# is), runs `hadynet
# residual MODEL TWIN --rated-range fc=0..50 --rated-range f=0..200 --fix
# --fix-min-excess-null 0` on it once (DIR/twin/seedS.json: its fix.control
# is fine-tuning alone on the twin; the rated ranges are the detection
# bench's; DIR/twin/model.txt holds the model's SHA-256 and the rows, and
# other twins are refused), writes a line per set to DIR/lines.txt and the table per
# case to DIR/summary.txt. Sets recorded under a re-zeroing
# (--rezeroed-first-init) are not supported: their twin would need the
# same zeroing.
# Environment: HADYNET (default build/release/cli/hadynet; a relative path is
# the repository's), RESIDUAL_ROWS.
#
# Data roles (stop 94): it chooses nothing (0.7 is issue 12's bar). Read on
# the blocks 4865-4884, 4950-4969, 4980-4999 and 5030-5039 of
# bench/residual_detection.sh, their twins on the same seeds; the model was
# trained on seeds 1 and 2001-2003 and its null's floor chosen on 11, 13-16
# and 181-184 (docs/residual-experiments.md, "The cut on the clean twin (stop 94)").
set -euo pipefail
usage() { sed -n '2,24p' "$0" | sed 's/^# \{0,1\}//'; }
# value OPTION ARG...: the option's value, or usage and exit 2 when it has none.
value() { [[ $# -ge 2 && -n "$2" ]] || { echo "residual_twin_cut: $1 needs a value" >&2; usage >&2; exit 2; }; }
out="" model="" trees=()
while (($#)); do
  case "$1" in
    -h | --help) usage; exit 0 ;;
    --out) value "$@"; out=$2; shift 2 ;;
    --model) value "$@"; model=$2; shift 2 ;;
    -*) echo "residual_twin_cut: unknown option $1" >&2; exit 2 ;;
    *) [[ -d "$1" ]] || { echo "residual_twin_cut: $1 is not a directory" >&2; exit 2; }
       trees+=("$(cd "$1" && pwd)"); shift ;;
  esac
done
[[ -n "$out" && -n "$model" && ${#trees[@]} -gt 0 ]] || { usage >&2; exit 2; }
[[ -f "$model" ]] || { echo "residual_twin_cut: $model not found" >&2; exit 2; }
model=$(cd "$(dirname "$model")" && pwd)/$(basename "$model")
mkdir -p "$out" && out=$(cd "$out" && pwd)
cd "$(dirname "$0")/.."
source bench/residual_grasps.sh
hadynet="${HADYNET:-build/release/cli/hadynet}"
[[ -x "$hadynet" ]] || { echo "residual_twin_cut: $hadynet not found" >&2; exit 2; }
mkdir -p "$out/clean" "$out/twin"
# The twins hold one model's fine-tuning on logs of one length: another's
# are refused, and so are twins of unknown origin (no model.txt).
key="$(sha256sum <"$model" | cut -d' ' -f1) rows=${RESIDUAL_ROWS:-300}"
if [[ -f "$out/twin/model.txt" ]]; then
  [[ "$(cat "$out/twin/model.txt")" == "$key" ]] ||
    { echo "residual_twin_cut: $out/twin holds another model's or row count's twins (model.txt)" >&2; exit 2; }
elif compgen -G "$out/twin/seed*.json" >/dev/null; then
  echo "residual_twin_cut: $out/twin holds twins without model.txt (of which model and rows?): use another --out" >&2
  exit 2
else
  echo "$key" >"$out/twin/model.txt"
fi
lines="$out/lines.txt"
: >"$lines"
mapfile -t sets < <(find "${trees[@]}" -path '*/seed*/residual.json' -printf '%h\n' | sort)
((${#sets[@]})) || { echo "residual_twin_cut: no set under ${trees[*]}" >&2; exit 2; }
start=$(date +%s) k=0
for d in "${sets[@]}"; do
  seed=${d##*/seed} case=$(basename "$(dirname "$d")")
  clean="$out/clean/seed$seed" twin="$out/twin/seed$seed.json"
  record_clean_twin "$hadynet" "$clean" "$seed" || { echo "residual_twin_cut: collect seed $seed failed" >&2; exit 1; }
  if [[ ! -f "$twin" ]]; then
    "$hadynet" residual "$model" "$clean" --rated-range fc=0..50 --rated-range f=0..200 --fix \
      --fix-min-excess-null 0 --json "$twin.part" >"$out/twin/seed$seed.txt" 2>&1 \
      || { echo "residual_twin_cut: residual on the twin of seed $seed failed ($out/twin/seed$seed.txt)" >&2; exit 1; }
    mv "$twin.part" "$twin"
  fi
  python3 bench/residual_twin_cut.py line "$case" "$seed" "$d" "$twin" | tee -a "$lines"
  k=$((k + 1))
  echo "[$k/${#sets[@]}, ETA $(( ($(date +%s) - start) * (${#sets[@]} - k) / k ))s]" >&2
done
python3 bench/residual_twin_cut.py table "$lines" | tee "$out/summary.txt"

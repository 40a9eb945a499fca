#!/usr/bin/env bash
# Recognition over many zeroings (issue 17; a benchmark, not a test): a user
# re-zeroes the hand every time it starts, so what matters is how often the
# grasped object is named right over many zeroings, and how wrong it is when
# it is wrong.
#
# For each zeroing it records the six trained objects' grasps (both motions,
# 500 rows: the paper's lengths) and Cylinder-L's, then `hadynet recognize`
# adapts one PB per grasp (as the paper: PB only, 20 full-batch epochs) and
# names the object (its default metric, docs/trainer.md; RECOGNIZE_ARGS="--metric
# nearest-state" for the paper's rule). bench/recognition_summary.py prints
# the accuracy per object, the confusion matrix, the margin (distance to the
# nearest wrong object over distance to the right one; < 1 is a miss) and
# where Cylinder-L lands (between Cylinder and Gripper or not).
#
# Zeroings (disjoint roles): the model was trained on inits 0-2 of dataset
# seed 1 (collect --preset paper), init 3 is the paper preset's test
# zeroing, inits 4-6 the validation zeroings of scripts/paper_experiments.sh
# (the only ones any option was chosen on). Measured here by default: inits
# 100-149 of seed 1, used for nothing else. The plant derives each
# experiment's encoder offsets from (init, seed, object)
# (host-sim/plant/hand_spec.cc), so every init is a new zeroing.
#
# Usage: bench/recognition_zeroings.sh [--model M] [--out DIR] [--jobs N] [INIT...]
#   defaults: models/hand.safetensors, build/recognition-zeroings, 2, 100..149
# Environment: HADYNET (default build/release/cli/hadynet); RECOGNIZE_ARGS,
# extra options of `hadynet recognize` (e.g. "--start objects").
# --keep-logs keeps each zeroing's logs (OUT/initN/logs) instead of deleting
# them after recognition (14 logs of 500 rows, about 4 MB per zeroing).
# Prints one line per zeroing with an ETA, then the summary; OUT/summary.txt.
set -euo pipefail
usage() { sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'; }
model=models/hand.safetensors
out=build/recognition-zeroings
jobs=2
keep_logs=0
inits=()
while (($#)); do
  case "$1" in
    -h | --help) usage; exit 0 ;;
    --model) model=$2; shift 2 ;;
    --out) out=$2; shift 2 ;;
    --jobs) jobs=$2; shift 2 ;;
    --keep-logs) keep_logs=1; shift ;;
    -*) echo "recognition_zeroings: unknown option $1" >&2; exit 2 ;;
    *) inits+=("$1"); shift ;;
  esac
done
cd "$(dirname "$0")/.."
((${#inits[@]})) || inits=($(seq 100 149))
hadynet="${HADYNET:-build/release/cli/hadynet}"
[[ -x "$hadynet" ]] || { echo "recognition_zeroings: $hadynet not found (scripts/build.sh release)" >&2; exit 2; }
objects=(None Hammer Hammer-S Cylinder Gripper Ball Cylinder-L)
mkdir -p "$out"
i=0 start=$(date +%s)
for init in "${inits[@]}"; do
  i=$((i + 1))
  d="$out/init$init"
  if [[ ! -f "$d/recognize.json" ]]; then  # a finished zeroing is kept (rerun to resume)
    if [[ ! -d "$d/logs" ]]; then  # kept logs (--keep-logs) are used again
      rm -rf "$d" && mkdir -p "$d"
      for o in "${objects[@]}"; do
        for m in random1 random2; do echo "$o $m"; done
      done | xargs -P "$jobs" -L 1 sh -c \
        "\"$hadynet\" collect --object \"\$0\" --motion \"\$1\" --init $init --split logs --out \"$d\" --quiet >/dev/null"
    fi
    # shellcheck disable=SC2086  # RECOGNIZE_ARGS: options, split on spaces
    "$hadynet" recognize "$model" "$d/logs" ${RECOGNIZE_ARGS:-} --json "$d/recognize.json" >"$d/recognize.txt" 2>&1 ||
      { echo "init $init: hadynet recognize failed: $(tail -1 "$d/recognize.txt")" >&2; exit 1; }
    ((keep_logs)) || rm -rf "$d/logs"  # the JSON keeps what the summary needs
  fi
  elapsed=$(($(date +%s) - start))
  eta=$((elapsed * (${#inits[@]} - i) / i))
  printf 'zeroing %3d/%d (init %d): %s  elapsed %ds, ETA %ds\n' "$i" "${#inits[@]}" "$init" \
    "$(grep -o 'accuracy: .*' "$d/recognize.txt" || echo '?')" "$elapsed" "$eta"
done
jsons=()
for init in "${inits[@]}"; do jsons+=("$out/init$init/recognize.json"); done
python3 bench/recognition_summary.py "${jsons[@]}" | tee "$out/summary.txt"

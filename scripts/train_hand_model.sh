#!/usr/bin/env bash
# Trains HADYNET on the paper preset recorded with several dataset seeds: the
# same 36 grasps (6 objects x Random-1/Random-2 x 3 zeroings, 500 rows) once
# per seed, each seed drawing other motions and noise (docs/plant.md). The
# states, and so the PBs, are the paper's 18; only the motions multiply.
# With one seed (1) this is how the build's model was trained
# (models/hand.safetensors, then calibrated for detection). With seeds 1
# 2001 2002 2003 it is the 4-seed model, models/hand-4seeds.safetensors
# (docs/residual.md, "A model that generalises"): the build's model fits
# fresh motions of its own states far worse than its held-out rows, and the
# residual loop then takes that misfit for effects.
# Training uses `hadynet train`'s defaults (200 epochs, 10-step windows, the
# last 10 % of each log held out and stored as the model's null) with 2
# threads: its bits depend on the seeds and the thread count, and 2 is what
# the committed model used, so a re-run reproduces it (about 2 s per epoch
# for four seeds on the project's 2-core VM).
#
# Usage: scripts/train_hand_model.sh [--seeds "S..."] [--data DIR] --out MODEL
#   defaults: --seeds "1 2001 2002 2003", --data build/hand-model-data (in
#   the repository; DIR/seed<S>: each seed's recording, reused when its
#   manifest is the paper preset of that seed and it validates). Relative
#   MODEL, DIR and HADYNET are the caller's. MODEL.ckpt, MODEL.loss.csv and
#   MODEL.loss.png are written beside MODEL.
# Environment: HADYNET (default build/release/cli/hadynet).
set -euo pipefail
usage() { sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'; }
seeds="1 2001 2002 2003"
data=build/hand-model-data   # relative to the repository
data_given=
out=
while (($#)); do
  [[ "$1" == -h || "$1" == --help ]] || (($# >= 2)) || { echo "train_hand_model: $1 needs a value (--help)" >&2; exit 2; }
  case "$1" in
    -h | --help) usage; exit 0 ;;
    --seeds) seeds=$2; shift 2 ;;
    --data) data=$2; data_given=1; shift 2 ;;
    --out) out=$2; shift 2 ;;
    *) echo "train_hand_model: unknown argument $1 (--help)" >&2; exit 2 ;;
  esac
done
[[ -n "$out" ]] || { echo "train_hand_model: --out MODEL is required (--help)" >&2; exit 2; }
out=$(realpath -m -- "$out")   # relative to the caller's directory, not the repository's
[[ -z "$data_given" ]] || data=$(realpath -m -- "$data")
[[ -z "${HADYNET:-}" ]] || HADYNET=$(realpath -m -- "$HADYNET")
read -r -a seed_list <<<"$seeds"
((${#seed_list[@]})) || { echo "train_hand_model: --seeds names no seed" >&2; exit 2; }
for s in "${seed_list[@]}"; do
  [[ "$s" =~ ^[0-9]+$ ]] || { echo "train_hand_model: seed '$s' is not a non-negative integer" >&2; exit 2; }
done
cd "$(dirname "$0")/.."
hadynet="${HADYNET:-build/release/cli/hadynet}"
[[ -x "$hadynet" ]] || { echo "train_hand_model: $hadynet not found (scripts/build.sh release)" >&2; exit 2; }
train_dirs=()
# recorded_already DIR SEED: DIR holds a complete paper-preset recording of
# SEED (collect writes the manifest last; validate checks every log in it).
recorded_already() {
  [[ -f "$1/manifest.json" ]] &&
    python3 -c 'import json, sys
m = json.load(open(sys.argv[1]))
sys.exit(0 if m.get("preset") == "paper" and m.get("seed") == int(sys.argv[2]) else 1)' "$1/manifest.json" "$2" &&
    "$hadynet" validate "$1" >/dev/null
}
for s in "${seed_list[@]}"; do
  d="$data/seed$s"
  if recorded_already "$d" "$s"; then
    echo "== seed $s: reusing $d"
  else
    echo "== collect --preset paper --seed $s -> $d (no complete recording of that seed there)"
    rm -rf "$d"
    "$hadynet" collect --preset paper --seed "$s" --out "$d" --quiet
  fi
  train_dirs+=("$d/train")
done
echo "== train on ${#train_dirs[@]} seed(s): ${seed_list[*]} -> $out"
"$hadynet" train "${train_dirs[@]}" --threads 2 --out "$out"

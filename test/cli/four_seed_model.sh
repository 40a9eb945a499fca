#!/usr/bin/env bash
# models/hand-4seeds.safetensors (scripts/train_hand_model.sh: the paper
# preset recorded with seeds 1, 2001, 2002 and 2003) exists because it fits
# fresh motions of the training states far better than the build's model,
# trained on seed 1 alone (docs/residual.md, "A model that generalises").
# Checked here on one clean set of the four grasps of docs/residual.md,
# recorded with seed 1191 (used for nothing else): `hadynet residual` with
# each model and the plant's rated ranges (as the benchmarks), the
# channel-mean 1-step fit (the report's "fit h=1", %) of the 4-seed model
# must beat the build model's by at least 4 points. Measured now: 57.6 %
# against 73.2 %.
# Tolerance: on the clean sets 1151-1170 (bench/residual_false_positives.sh)
# the gap is 8.7-31.5 points (mean 16.8); 4 is about half the smallest, so a
# 4-seed model that lost most of its advantage (trained on one seed, or a
# broken retraining) fails. About 17 s on the development VM.
#   four_seed_model.sh HADYNET BUILD_MODEL FOUR_SEED_MODEL WORKDIR
set -uo pipefail
hadynet=$1 build_model=$2 four_seed_model=$3 work=$4
min_gap=4
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 2
fail() { echo "FAIL: $*"; exit 1; }

for g in "Cylinder random2 1" "Ball random2 2" "Gripper random2 0" "Cylinder random1 0"; do
  set -- $g
  "$hadynet" collect --object "$1" --motion "$2" --init "$3" --rows 300 --seed 1191 --out logs --quiet >/dev/null ||
    fail "collect $g"
done

mean_fit() { # JSON -> the channel-mean 1-step fit, %
  python3 -c 'import json, sys
fit = json.load(open(sys.argv[1]))["multi_step"]["fit_percent"]
print(sum(v[0] for v in fit.values()) / len(fit))' "$1"
}
for m in build four_seed; do
  model_var=${m}_model
  "$hadynet" residual "${!model_var}" logs --rated-range fc=0..50 --rated-range f=0..200 --json "$m.json" >"$m.txt" 2>&1 ||
    fail "residual with the $m model exited $?: $(tail -3 "$m.txt")"
done
build_fit=$(mean_fit build.json) || fail "reading the build model's fit"
four_seed_fit=$(mean_fit four_seed.json) || fail "reading the 4-seed model's fit"
printf "channel-mean 1-step fit: build model %.1f %%, 4-seed model %.1f %% (at least %s points better required)\n" \
  "$build_fit" "$four_seed_fit" "$min_gap"
python3 -c 'import sys; sys.exit(0 if float(sys.argv[2]) - float(sys.argv[1]) >= float(sys.argv[3]) else 1)' \
  "$build_fit" "$four_seed_fit" "$min_gap" || fail "the 4-seed model does not fit fresh motions clearly better"
echo "PASS"

#!/usr/bin/env bash
# Variable vs constant PB over training seeds (issue 17; a benchmark, not a
# test). The seed paper reports a training loss about 20 % lower with a
# variable PB than with a constant one; one training run says little about
# a difference of that size, so this trains both variants with several
# training seeds (default 1, 2, 3) on the same paper-preset dataset (dataset
# seed 1, collected into OUT/data if absent) and reports the final training
# loss and the loss on the held-out windows (the last 10 % of every training
# log's windows, never trained on), with the mean and the range over seeds.
# The held-out windows are new windows of the training records (the same
# zeroings, inits 0-2): they measure the fit of unseen stretches of known
# states, not a new zeroing (bench/recognition_zeroings.sh does that).
#
# Usage: bench/variable_pb_seeds.sh [--out DIR] [--epochs N] [SEED...]
#   defaults: build/variable-pb-seeds, 200 epochs (the paper preset's), 1 2 3
# Environment: HADYNET (default build/release/cli/hadynet).
# Prints one line per trained model with an ETA, then the table; OUT/summary.txt.
set -euo pipefail
usage() { sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'; }
out=build/variable-pb-seeds
epochs=200
seeds=()
while (($#)); do
  case "$1" in
    -h | --help) usage; exit 0 ;;
    --out) out=$2; shift 2 ;;
    --epochs) epochs=$2; shift 2 ;;
    -*) echo "variable_pb_seeds: unknown option $1" >&2; exit 2 ;;
    *) seeds+=("$1"); shift ;;
  esac
done
cd "$(dirname "$0")/.."
((${#seeds[@]})) || seeds=(1 2 3)
hadynet="${HADYNET:-build/release/cli/hadynet}"
[[ -x "$hadynet" ]] || { echo "variable_pb_seeds: $hadynet not found (scripts/build.sh release)" >&2; exit 2; }
mkdir -p "$out"
[[ -d "$out/data/train" ]] || "$hadynet" collect --preset paper --seed 1 --out "$out/data" --quiet
runs=$((2 * ${#seeds[@]})) i=0 start=$(date +%s)
for seed in "${seeds[@]}"; do
  for variant in variable constant; do
    i=$((i + 1))
    model="$out/${variant}_seed$seed.safetensors"
    if [[ ! -f "$model" ]]; then
      flag=()
      [[ $variant == constant ]] && flag=(--constant-pb)
      "$hadynet" train "$out/data/train" --out "$model" --seed "$seed" --epochs "$epochs" --quiet "${flag[@]}" \
        >"$model.txt" 2>&1 || { echo "variable_pb_seeds: training failed, see $model.txt" >&2; exit 1; }
    fi
    elapsed=$(($(date +%s) - start))
    printf 'model %d/%d (%s PB, seed %d): %s  elapsed %ds, ETA %ds\n' "$i" "$runs" "$variant" "$seed" \
      "$(tail -1 "$model.loss.csv")" "$elapsed" $((elapsed * (runs - i) / i))
  done
done
# The last row of each loss CSV: epoch, train loss, held-out loss.
for seed in "${seeds[@]}"; do
  echo "$seed $(tail -1 "$out/variable_seed$seed.safetensors.loss.csv") $(tail -1 "$out/constant_seed$seed.safetensors.loss.csv")"
done | awk -v epochs="$epochs" '
  { split($2, v, ","); split($3, c, ",");
    tr[NR] = 100 * (1 - v[2] / c[2]); ho[NR] = 100 * (1 - v[3] / c[3]);
    printf "seed %s: train %.5f vs %.5f (variable %.1f %% lower), held-out %.5f vs %.5f (%.1f %% lower)\n",
           $1, v[2], c[2], tr[NR], v[3], c[3], ho[NR] }
  END {
    for (k = 1; k <= NR; ++k) { st += tr[k]; sh += ho[k];
      if (k == 1 || tr[k] < trmin) trmin = tr[k]; if (k == 1 || tr[k] > trmax) trmax = tr[k];
      if (k == 1 || ho[k] < homin) homin = ho[k]; if (k == 1 || ho[k] > homax) homax = ho[k] }
    printf "over %d training seeds (%d epochs): variable PB lower by %.1f %% on the training loss (range %.1f .. %.1f), %.1f %% on the held-out windows (range %.1f .. %.1f)\n",
           NR, epochs, st / NR, trmin, trmax, sh / NR, homin, homax }' | tee "$out/summary.txt"

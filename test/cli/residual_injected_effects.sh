#!/usr/bin/env bash
# Issue 12's findings 1 and 3 on the path a user takes: clean logs of the
# four grasps of docs/residual.md recorded with --seed 11 (the issue's seed;
# never used for training, but among the seeds the null's floor was chosen
# on, so these runs are a test, not a measurement: the measured figures are
# on fresh seeds, below), and effects added to them after recording by
# test/cli/inject_effect.py, made by nothing in the plant and declared
# nowhere, then `hadynet residual MODEL LOGS --fix` with the plant's rated
# ranges and every other setting a default (the stored null, --pb auto,
# candidates down to 1, two folds). Before (the issue): the clean logs
# gave a confident cross-talk that --fix applied, none of the added effects
# was named, the clean logs' false positive won four times and the tension
# leak was fixed as a lower rail by clipping.
#
# The cases and their strengths were fixed before the first run and not
# changed after (fresh seeds 1558-1561 and 1572-1581 with the same cases:
# docs/residual-experiments.md, "Effects added after recording"):
#   clean                  nothing confirmed, no model written;
#   delay:fc3:2            one loadcell 2 steps late: its delay, fc3 the winner;
#   drift:f:0.002          every tension drifts with its load at 0.002 /s: a
#                          load drift on tensions, each rate re-estimated
#                          within 0.5-1.5 times 0.002;
#   leak:f5:fc6:0.2        tension f5 leaks into the palm loadcell fc6: the
#                          cross-talk f5 -> fc6, gain within 0.5-1.5 times 0.2;
#   backlash:fc3:1         a 1 N play on one loadcell (a hysteresis of the
#                          sensor; no library effect is one): nothing confirmed;
#   cyclic:l3:0.05:0.5     an encoder's interpolation error on a tendon length
#                          (static, outside the library): nothing confirmed.
# A named effect must also cut its winner's held-out 1-step RMSE to at most
# 0.7 of before and below fine-tuning alone (the issue's 30 % cut and its
# control). The rules: test/cli/injected_effect_check.py.
#
# SEED (default 11) records the clean logs with another seed. Seed 1569
# (docs/residual-experiments.md, "The family alone beside its group"): the 2-step delay
# on fc3 alone also passed the test on other loadcells (through the
# network, which reads fc3), the delay planned on fc3 and those lost the
# selection on the training rows (p 0.998), and stop 50's code confirmed
# friction on fc3 (p 1.6e-4), a wrong class; now the same delay on the
# family alone (fc3) is a candidate too, gains significantly on the
# training rows (p 0.0004) and is confirmed (p 1e-4). (Seed 1557, where
# this was first seen, chooses the family alone as the clearest gain, p
# 0.017 against friction's 0.032: too close to stay on every CPU.)
#   residual_injected_effects.sh CASE HADYNET MODEL WORKDIR [SEED]
set -uo pipefail
case=$1 hadynet=$2 model=$3 work=$4 seed=${5:-11}
here=$(cd "$(dirname "$0")/../.." && pwd)
rm -rf "$work" && mkdir -p "$work" || exit 2
source "$here/bench/residual_grasps.sh"
RESIDUAL_ROWS=300 collect_residual_grasps "$hadynet" "$work/raw" "$seed" || { echo "FAIL: collect"; exit 1; }
[[ $(find "$work/raw" -name "*.csv" | wc -l) -eq 4 ]] || { echo "FAIL: not the four grasps' logs"; exit 1; }
if [[ $case == clean ]]; then
  mkdir -p "$work/logs" && find "$work/raw" -name "*.csv" -exec cp {} "$work/logs/" \;
else
  python3 "$here/test/cli/inject_effect.py" "$case" "$work/raw" "$work/logs" || { echo "FAIL: inject $case"; exit 1; }
fi
"$hadynet" residual "$model" "$work/logs" --rated-range fc=0..50 --rated-range f=0..200 --fix \
  --json "$work/residual.json" --out "$work/fixed.safetensors" >"$work/out.txt" 2>&1 \
  || { echo "FAIL: residual"; tail -5 "$work/out.txt"; exit 1; }
python3 "$here/test/cli/injected_effect_check.py" "$case" "$work/residual.json" "$work/fixed.safetensors"

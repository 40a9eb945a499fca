#!/usr/bin/env bash
# The plant's dry friction on every tendon (friction=4) on fresh logs (seed
# 3132, the four grasps of docs/residual.md, 300 rows), through `hadynet
# residual MODEL LOGS --fix` with the plant's rated ranges and every other
# setting a default: friction must be named on tendon channels (the
# detection bench's rule, bench/residual_named.py), its cut over the changed
# channels at most 0.7 and below fine-tuning alone
# (bench/residual_run_line.py). Until stop 72 the sign and hysteresis inputs
# the fix adds at zero weight learned at the fine-tuning's learning rate,
# and 20 epochs took them part of the way: confirmed (p 0.0065) and cut to
# 0.71 of before, a miss of the bench's bar. Since stop 72 those weights
# learn at 3 times the rate (--fix-derived-input-lr-scale; docs/residual.md,
# "The derived inputs' learning rate"): cut to 0.68 on the development VM.
# Seed 3132 was a development seed of that step. About 40 s on the
# development VM.
#   residual_friction_cut_test.sh HADYNET MODEL WORKDIR
set -uo pipefail
hadynet=$1 model=$2 work=$3
here=$(cd "$(dirname "$0")/../.." && pwd)
source "$here/test/cli/plant_fix_run.sh"
plant_fix_run "$hadynet" "$model" "$work" 3132 -- --effect friction=4 || exit 1
grep -E "^(fix|decision)" "$work/out.txt" | cut -c1-400
python3 - "$work/residual.json" "$here/bench" "$here/test/cli" <<'PY'
import sys
sys.path[:0] = sys.argv[2:4]
from plant_fix_checks import checked_fix, named_with_cut
fix, aug, check, finish = checked_fix(sys.argv[1])
named_with_cut("friction=4", 3132, sys.argv[1], check)
check(fix.get("derived_input_lr_scale") == 3, "the derived inputs' learning-rate scale is not the default 3")
finish()
PY

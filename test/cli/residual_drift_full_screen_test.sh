#!/usr/bin/env bash
# The plant's load drift of every loadcell (drift=0.02) on fresh logs (seed
# 3161, the four grasps of docs/residual.md, 300 rows), through `hadynet
# residual MODEL LOGS --fix` with the plant's rated ranges and every other
# setting a default: the drift must be named with its rate (the detection
# bench's rule, bench/residual_named.py), its cut over the changed channels
# at most 0.7 and below fine-tuning alone (bench/residual_run_line.py).
# Until stop 72 the screen's five candidates (two cross-talks, two curves
# and a rail) filled every place and none was a load drift, so the drift
# probe did not run; the selection took the cross-talk fc3 -> fc4 (the
# clearest gain, p 0.092 on the selection's rows) and the decision
# confirmed it (p 0.0021): a wrong fix. Since stop 72 the probe runs there
# too and its plan comes last, beyond --candidates (drift_probe_place();
# docs/residual-experiments.md, "The drift probe behind a full screen"). Seed 3161 was
# a development seed of that step. About 40 s on the development VM.
#   residual_drift_full_screen_test.sh HADYNET MODEL WORKDIR
set -uo pipefail
hadynet=$1 model=$2 work=$3
here=$(cd "$(dirname "$0")/../.." && pwd)
source "$here/test/cli/plant_fix_run.sh"
plant_fix_run "$hadynet" "$model" "$work" 3161 -- --effect drift=0.02 || exit 1
grep -E "^(fix|decision)" "$work/out.txt" | cut -c1-400
python3 - "$work/residual.json" "$here/bench" "$here/test/cli" <<'PY'
import sys
sys.path[:0] = sys.argv[2:4]
from plant_fix_checks import checked_fix, named_with_cut
fix, aug, check, finish = checked_fix(sys.argv[1])
named_with_cut("drift=0.02", 3161, sys.argv[1], check)
check(any(c.get("from_drift_probe") for c in fix.get("candidates", [])), "no candidate of the drift probe")
finish()
PY

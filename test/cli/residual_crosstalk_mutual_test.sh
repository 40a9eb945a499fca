#!/usr/bin/env bash
# The plant's fingertip cross-talk at 0.35 (crosstalk=0.35: each fingertip
# loadcell adds 0.35 times its neighbour's force; ring and little read each
# other) on fresh logs (seed 2327, the four grasps of docs/residual.md, 300
# rows), through `hadynet residual MODEL LOGS --fix` with the plant's rated
# ranges and every other setting a default: a plant pair must be named with
# every pair the fix removes one of the plant's (the detection bench's
# rule, bench/residual_named.py), confirmed, and cut the lead channel's
# held-out error by 30 % below fine-tuning alone, with the loadcells as a
# whole below fine-tuning alone (plant_fix_checks.py); and no pair the fix
# removes beside the winner's may be a side of the plant's mutual pair
# (fc3 -> fc4 and fc4 -> fc3, both significant on these logs). Until stop 62 the group's extension took
# fc3 -> fc4 against fc4 -> fc3: removing one side of a mutual pair against
# its measured source is biased (the source holds the target), fc4's and
# fc3's held-out errors rose above fine-tuning alone's, and the decision
# did not confirm (p 0.2; "unexplained structure"). Since stop 63 the
# extension leaves mutual pairs out (crosstalk::plan; docs/residual-experiments.md,
# "A mutual pair is not extended"): confirmed at p 5.4e-08 on the
# development VM. Seed 2327 was a development seed of this step (the miss
# it mends). About 60 s on the development VM.
#   residual_crosstalk_mutual_test.sh HADYNET MODEL WORKDIR
set -uo pipefail
hadynet=$1 model=$2 work=$3
here=$(cd "$(dirname "$0")/../.." && pwd)
source "$here/test/cli/plant_fix_run.sh"
plant_fix_run "$hadynet" "$model" "$work" 2327 -- --effect crosstalk=0.35 || exit 1
grep -E "^(fix|decision)|^  [ *] crosstalk" "$work/out.txt" | cut -c1-160
python3 - "$work/residual.json" "$here/bench" "$here/test/cli" <<'PY'
import sys
sys.path[:0] = sys.argv[2:4]
from residual_named import names
from plant_fix_checks import checked_fix, lead_and_loadcells
fix, aug, check, finish = checked_fix(sys.argv[1])
check(bool(fix.get("changed")), "nothing confirmed: " + fix.get("status", "")[:120])
check(names("crosstalk", 0.35, fix), "not the plant's cross-talk: " + aug.get("effect", "-") + ": " +
      aug.get("description", "")[:100])
# The plant's mutual pair (fc3 <-> fc4, both significant on these logs) is no extension.
for p in aug.get("pairs", [])[1:]:
    check({p["source"], p["target"]} != {"fc3", "fc4"}, "extended to one side of the mutual pair: " + p["source"] +
          " -> " + p["target"])
print("pairs removed:", ", ".join(p["source"] + " -> " + p["target"] for p in aug.get("pairs", [])))
lead_and_loadcells(fix, check)
finish()
PY

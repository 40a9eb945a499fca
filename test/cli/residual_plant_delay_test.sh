#!/usr/bin/env bash
# The plant's 2-step delay of every loadcell on fresh logs (seed 1583, the
# four grasps of docs/residual.md, 300 rows), through `hadynet residual
# MODEL LOGS --fix` with the plant's rated ranges and every other setting a
# default: the delay must be aligned on at least 8 of the 9 loadcells (the
# ninth, a loadcell that rarely touches anything, may stay late: the test of
# every channel of the group has little power on it), not on the few its
# family alone holds (docs/residual-experiments.md, "Wider plans,
# tested after the confirmation"). Before stop 52 the family alone (fc4,
# fc3, fc1, fc2) was confirmed and applied, the five other loadcells stayed
# late and the fixed model predicted fc6 1.33 times worse than fine-tuning
# alone. Now the extended plan is tested against the family alone on the
# channels it adds and applied (p 2e-5 on this machine). Either path that
# aligns the group passes: on another CPU the selection may choose the
# extended plan at once (its training-rows p is 0.0103, at alpha 0.01); the
# wider plans' tests must be reported either way (fix.extensions, which
# stop 51's code lacks), and a family alone, when chosen, extended.
# Also checked: the lead's held-out RMSE cut by 30 % and below fine-tuning
# alone (issue 12's bar), and the summed loadcell RMSE below fine-tuning
# alone's (the group as a whole is better, not only the channels claimed).
#   residual_plant_delay_test.sh HADYNET MODEL WORKDIR
set -uo pipefail
hadynet=$1 model=$2 work=$3
here=$(cd "$(dirname "$0")/../.." && pwd)
source "$here/test/cli/plant_fix_run.sh"
plant_fix_run "$hadynet" "$model" "$work" 1583 -- --effect sensor-delay=2 || exit 1
grep -E "^(decision|Extension)" "$work/out.txt"
python3 - "$work/residual.json" "$here/test/cli" <<'PY'
import sys
sys.path.insert(0, sys.argv[2])
from plant_fix_checks import checked_fix, lead_and_loadcells
fix, aug, check, finish = checked_fix(sys.argv[1])
channels = aug.get("channels", [])
check(bool(fix.get("changed")), "nothing confirmed: " + fix.get("status", "")[:120])
check(aug.get("effect") == "sensor-delay" and aug.get("delay_steps") == 2, "not a 2-step sensor delay: " + aug.get("effect", "-"))
print("aligned:", channels)
check(len(channels) >= 8 and all(c.startswith("fc") for c in channels), f"aligned on {len(channels)} loadcells, not 8 or more")
# The wider plans are tested and reported (stop 51's code has no such field),
# and a family alone chosen by the selection was extended by the first.
extensions = fix.get("extensions")
check(isinstance(extensions, list), "no fix.extensions")
for e in extensions or []:
    print(f"extension to {e['what']}: {e['channels']}, p {e['p_value']:.2g}, applied {e['applied']}")
family_alone_first = bool(extensions) and extensions[0]["what"].startswith("its group's channels")
check(not family_alone_first or extensions[0]["applied"], "the family alone was not extended to its group")
lead_and_loadcells(fix, check)
finish()
PY

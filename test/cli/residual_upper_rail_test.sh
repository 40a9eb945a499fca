#!/usr/bin/env bash
# The plant's 2 N rail on the loadcells (saturation=2) on fresh logs (the
# four grasps of docs/residual.md, 300 rows, recorded with seed 4791),
# through `hadynet residual MODEL LOGS --fix` with the plant's rated ranges
# and every other setting a default. The screen finds upper rails of the
# loadcells at Holm's level: fc7's at 2.04 N explains 0.74 of fc7's
# held-out residual variance with a gain of 1.01 (the residual follows the
# prediction's excess over the rail one for one), and the plan's lead, fc3's
# at 2.06 N, 0.39 of fc3's; but their excess over the null is 0.28 and 0.50
# times the channel's clean residual level, below the candidates' floor of
# 1: the network carries the clipped reading over from its input, so a rail
# leaves a small 1-step residual. Until stop 89 the screen proposed nothing and the run
# ended "no significant effect". Since stop 90 an upper rail is a candidate
# down to --fix-upper-rail-floor (0: any excess over the null) when every
# other test of the screen passes (docs/residual-experiments.md, "An upper rail below
# the candidates' floor (stop 90)").
# Checked: a rail below the candidates' floor is among the candidates (the
# rule let it in), it is confirmed and applied; it is named (every rail
# within 10 % of 2 N: the bench's rule, bench/residual_named.py), and its
# held-out RMSE on the channels it clips is cut by 30 % and below
# fine-tuning alone (the bench's rule, bench/residual_run_line.py: 0.54
# here). 4791 is a development set of the rule (stop 90's block 4790-4799,
# stop 89's code). About 15 s on the development VM.
#   residual_upper_rail_test.sh HADYNET MODEL WORKDIR
set -uo pipefail
hadynet=$1 model=$2 work=$3
here=$(cd "$(dirname "$0")/../.." && pwd)
source "$here/test/cli/plant_fix_run.sh"
plant_fix_run "$hadynet" "$model" "$work" 4791 -- --effect saturation=2 || exit 1
grep -E "^(verdict|fix|decision)" "$work/out.txt" | cut -c1-400
python3 - "$work/residual.json" "$here/bench" "$here/test/cli" <<'PY'
import re, sys
sys.path[:0] = sys.argv[2:4]
from plant_fix_checks import checked_fix
from residual_run_line import run_line
fix, aug, check, finish = checked_fix(sys.argv[1])
line = run_line("saturation=2", 4791, sys.argv[1], "")
print(line)
check(re.search(r"named yes cut yes .*<control yes", line) is not None,
      "not named, or not cut by 30 % below fine-tuning alone")
floor = fix.get("candidates_floor")
check(fix.get("upper_rail_floor") == 0 and floor is not None, "no upper rail's floor below the candidates' floor")
candidates = fix.get("candidates", [])
# The screen's own candidates (not the chosen curve's rail, the drift
# probe's or an earlier round's) marked below its floor, and below the
# candidates' floor too: only the upper rail's floor lets such a rail in.
below = [c for c in candidates if c["effect"] == "saturation" and c.get("below_screen_floor")
         and not c.get("rail_of_chosen_curve") and not c.get("from_drift_probe")
         and not c.get("from_earlier_round") and floor is not None and c["screen_statistic"] < floor]
check(bool(below), "no rail below the candidates' floor among the screen's candidates (the rule did not act)")
check(all(c["effect"] == "saturation" for c in candidates), "a candidate other than a rail (the screen proposed one itself)")
check(aug.get("effect") == "saturation", "the rail is not the change applied")
finish()
PY

#!/usr/bin/env bash
# The plant's friction (friction=4) on fresh logs (the four grasps of
# docs/residual.md, 300 rows, recorded with seed 4609), through `hadynet
# residual MODEL LOGS --fix` with the plant's rated ranges and every other
# setting a default. No candidate gains significantly on the selection's
# rows, and the clearest gain (Diebold-Mariano statistic 1.96 against
# friction's 0.71) is a calibration curve of three finger lengths (l2, l0,
# l1: the model's misfit of a fresh zeroing), which the held-out rows
# reject (p 0.15). Friction gained 13 times more than the curve there (a
# larger gain, less even) but, being no rival of a curve of another
# group, was never tested until stop 88, and the run ended with
# "unexplained structure". Since then every choice has the plans of the
# groups it does not hold that gained more than it as rivals
# (decision_rivals(), rival_gain_floor(); docs/residual-experiments.md, "Every
# choice's rivals: the plans of other groups that gained more"): friction
# is tested beside the curve, confirmed (p 3.3e-4, Holm's level 0.005) and
# applied.
# Checked: the selection's choice is a curve of the lengths, not confirmed
# itself; friction gained more than it on the selection's rows (the path
# through rival_gain_floor), is a rival confirmed and applied, and its
# held-out RMSE on the channels it changes is cut by 30 % and below
# fine-tuning alone (the bench's rule, bench/residual_run_line.py: 0.59
# here). The bench's naming rule is not required: friction is confirmed on
# the tendons f2, f1, f0 and f5 and on the joint angle th0, and the rule
# names friction on tendons only. The margins were chosen so that small
# numerical differences between machines keep the path (4602, the other
# friction set of the diagnosis, chooses the curve at a statistic of 2.08
# against friction's 1.85). 4609 is a fresh set of stop 87, a development
# set of stop 88. About 40 s on the development VM.
#   residual_other_group_rival_test.sh HADYNET MODEL WORKDIR
set -uo pipefail
hadynet=$1 model=$2 work=$3
here=$(cd "$(dirname "$0")/../.." && pwd)
source "$here/test/cli/plant_fix_run.sh"
plant_fix_run "$hadynet" "$model" "$work" 4609 -- --effect friction=4 || exit 1
grep -E "^(fix|decision|Rivals)" "$work/out.txt" | cut -c1-400
python3 - "$work/residual.json" "$here/bench" "$here/test/cli" <<'PY'
import re, sys
sys.path[:0] = sys.argv[2:4]
from plant_fix_checks import checked_fix
from residual_run_line import run_line
fix, aug, check, finish = checked_fix(sys.argv[1])
line = run_line("friction=4", 4609, sys.argv[1], "")
print(line)
check(re.search(r"cut yes .*<control yes", line) is not None, "not cut by 30 % below fine-tuning alone")
chosen = [c for c in fix.get("candidates", []) if c.get("chosen")]
check(bool(chosen) and chosen[0]["effect"] == "sensor-curve" and
      re.search(r"curve for l\d", chosen[0].get("description", "")) is not None,
      "the selection did not choose a curve of the finger lengths")
rivals = fix.get("rivals") or {}
check(rivals.get("chosen_confirmed") is False, "the chosen curve was confirmed, or there were no rivals")
applied = [p for p in rivals.get("plans", []) if p.get("applied")]
check(len(applied) == 1 and applied[0]["effect"] == "friction", "friction not applied as a rival")
friction = [c for c in fix.get("candidates", []) if c["effect"] == "friction"]
check(bool(chosen) and bool(friction) and
      friction[0]["selection_mean_loss_difference"] > chosen[0]["selection_mean_loss_difference"],
      "friction did not gain more than the chosen curve on the selection's rows")
check(aug.get("effect") == "friction", "friction is not the change applied")
finish()
PY

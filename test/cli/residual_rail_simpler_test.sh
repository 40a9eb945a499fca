#!/usr/bin/env bash
# The plant's 2 N rail of every loadcell on fresh logs (seed 1595, the four
# grasps of docs/residual.md, 300 rows), through `hadynet residual MODEL
# LOGS --fix` with the plant's rated ranges and every other setting a
# default: the rail must be named with its level (within 10 % of 2 N, the
# detection bench's rule), not the calibration curve that imitates it
# (docs/residual-experiments.md, "The simpler account: a rail before a curve"). Before
# stop 53 the selection chose a curve of fc4 and six other loadcells as
# the clearest gain, the decision confirmed it (p 0.0094) and it was
# applied. Now the rail of the curve's lead channel, confirmed against
# fine-tuning alone on its own rows (p 0.00075 on this machine), replaces
# it, since the curve does not predict the channels either claims
# significantly better (p 0.039, at alpha 0.01), and its extension to the
# group follows. On another CPU the selection may choose a rail at
# once; either path passes, but a curve chosen must be followed by the
# simpler account, reported (fix.simpler, which stop 52's code lacks) and
# applied, or by the group's rail tested beside it as its rival (since
# stop 70) and applied: with each log in its own level (stop 77,
# --decision-pooling logs, not the default) the curve is confirmed (p
# 0.00045) and the rail of fc4, fc3, fc7 and fc6 beside it (p 0.00014)
# predicts best, so the rail is applied that way. Also checked: the
# lead's held-out RMSE cut by 30 % and below fine-tuning alone (issue
# 12's bar), and the summed loadcell RMSE below fine-tuning alone's.
# Seed 1595 was a development seed of this step (the miss it mends).
#   residual_rail_simpler_test.sh HADYNET MODEL WORKDIR
set -uo pipefail
hadynet=$1 model=$2 work=$3
here=$(cd "$(dirname "$0")/../.." && pwd)
source "$here/test/cli/plant_fix_run.sh"
plant_fix_run "$hadynet" "$model" "$work" 1595 -- --effect saturation=2 || exit 1
grep -E "^(fix|decision|Simpler|Extension)" "$work/out.txt"
python3 - "$work/residual.json" "$here/bench" "$here/test/cli" <<'PY'
import sys
sys.path[:0] = sys.argv[2:4]
from residual_named import names
from plant_fix_checks import checked_fix, lead_and_loadcells
fix, aug, check, finish = checked_fix(sys.argv[1])
check(bool(fix.get("changed")), "nothing confirmed: " + fix.get("status", "")[:120])
check(names("saturation", 2.0, fix), "not the 2 N rail: " + aug.get("effect", "-") + ": " + aug.get("description", "")[:100])
chosen = [c for c in fix.get("candidates", []) if c.get("chosen")]
simpler = fix.get("simpler")
rival_rail = any(p.get("applied") and p["effect"] == "saturation" for p in (fix.get("rivals") or {}).get("plans", []))
if chosen and chosen[0]["effect"] == "sensor-curve":
    check((simpler is not None and simpler.get("applied")) or rival_rail,
          "a curve chosen and neither the simpler account nor a rival rail applied")
if simpler:
    g = simpler.get("confirmed_gain", {})
    print(f"simpler account: {simpler['effect']} on {simpler['channels']} in place of {simpler['replaces']}: "
          f"p {simpler['against_reference']['p_value']:.2g} against fine-tuning alone, "
          f"the curve's gain p {g.get('p_value', float('nan')):.2g}, applied {simpler['applied']}")
lead_and_loadcells(fix, check)
finish()
PY

#!/usr/bin/env bash
# The plant's load drift of every loadcell (drift=0.02) on fresh logs (seed
# 3000, the four grasps of docs/residual.md, 300 rows), through `hadynet
# residual MODEL LOGS --fix` with the plant's rated ranges and every other
# setting a default: the drift must be named with its rate (the detection
# bench's rule, bench/residual_named.py), its cut over the changed channels
# at most 0.7 and below fine-tuning alone (bench/residual_run_line.py).
# Until stop 71 the selection chose the screen's family of fc3, fc6 and fc0
# (it predicted the selection's rows a little better than the drift probe's
# plan of the nine loadcells: gives_way_to_group_drift kept it), and the
# decision did not confirm it on the held-out rows (p 0.013 > 0.01):
# "unexplained structure". Since stop 71 a chosen load drift has the drift
# probe's plans as rivals (decision_rivals(); docs/residual-experiments.md,
# "Every group the probe finds, its plans as a drift's rivals"): the group's plan is tested beside the
# family at Holm's levels and confirmed there (p 1.1e-06 on the development
# VM). On another CPU the selection may choose the group's plan at once;
# either path passes, but a family of the loadcells chosen there must have
# the probe's plan of the loadcells tested beside it (in fix.rivals, which
# stop 70's code lacks). Seed 3000 was a development seed of this step (a
# miss of stop 70 it mends). About 40 s on the development VM.
#   residual_drift_group_rival_test.sh HADYNET MODEL WORKDIR
set -uo pipefail
hadynet=$1 model=$2 work=$3
here=$(cd "$(dirname "$0")/../.." && pwd)
source "$here/test/cli/plant_fix_run.sh"
plant_fix_run "$hadynet" "$model" "$work" 3000 -- --effect drift=0.02 || exit 1
grep -E "^(fix|decision|Rivals)" "$work/out.txt" | cut -c1-400
python3 - "$work/residual.json" "$here/bench" "$here/test/cli" <<'PY'
import sys
sys.path[:0] = sys.argv[2:4]
from plant_fix_checks import checked_fix, named_with_cut
fix, aug, check, finish = checked_fix(sys.argv[1])
named_with_cut("drift=0.02", 3000, sys.argv[1], check)
candidates = fix.get("candidates", [])
chosen = [k for k, c in enumerate(candidates) if c.get("chosen")]
if chosen:
    c = candidates[chosen[0]]
    if c["effect"] == "drift-load" and not c.get("from_drift_probe"):
        probes = [k for k, p in enumerate(candidates) if p.get("from_drift_probe") and
                  all(ch.startswith("fc") for ch in p["channels"])]
        rivals = [r["candidate"] for r in (fix.get("rivals") or {}).get("plans", [])]
        check(any(k in rivals for k in probes),
              "a family of loadcells chosen and the probe's plan of the loadcells not tested beside it")
finish()
PY

#!/usr/bin/env bash
# Two plant effects at once, a 2-step delay of every loadcell and friction
# (sensor-delay=2, friction=4), on fresh logs (seed 2283, the four grasps
# of docs/residual.md, 300 rows), through `hadynet residual MODEL LOGS
# --fix --rounds 2` with the plant's rated ranges and every other setting a
# default: both must be named with their parameter and confirmed, one per
# round (the two-effect bench's "both"; bench/residual_named.py's rules).
# Round 1 confirms friction, whose fine-tuning on these logs absorbs part of
# the delay (its 2-step gain on fc3 and fc4 read 0.41-0.48 after it, under
# the screen's bound of 0.5), so before stop 62 round 2's screen proposed
# nothing ("no significant effect"). Now round 2 also tries round 1's
# candidates it did not apply (FixOptions::earlier_candidates): the time
# alignment, confirmed against fine-tuning alone at p 1e-07 on this machine.
# On another CPU round 1 may confirm the delay first; then round 2's screen
# finds friction itself (the delay's alignment absorbs nothing of it), and
# that path passes too, but a round-2 candidate carried from round 1 must
# be labelled so in the JSON. Seed 2283 was a development seed of this step
# (the miss it mends; docs/residual-experiments.md, "An earlier round's candidates").
# About 60 s on the development VM.
#   residual_rounds_earlier_test.sh HADYNET MODEL WORKDIR
set -uo pipefail
hadynet=$1 model=$2 work=$3
here=$(cd "$(dirname "$0")/../.." && pwd)
source "$here/test/cli/plant_fix_run.sh"
plant_fix_run "$hadynet" "$model" "$work" 2283 --rounds 2 -- --effect sensor-delay=2 --effect friction=4 || exit 1
grep -E "^(fix|decision|rounds)|=== round|an earlier round's" "$work/out.txt" | cut -c1-160
python3 - "$work/residual.json" "$here/bench" <<'PY'
import json, sys
sys.path.insert(0, sys.argv[2])
from residual_named import names
j = json.load(open(sys.argv[1]))
rounds = [j] + j.get("rounds", [])
failures = []
confirmed = {}  # plant effect -> the round that confirmed it, named with its parameter
for r in rounds:
    fix = r.get("fix", {})
    for effect, strength in (("sensor-delay", 2), ("friction", 4)):
        if fix.get("changed") and names(effect, strength, fix):
            confirmed[effect] = r.get("round", 1)
for effect in ("sensor-delay", "friction"):
    if effect not in confirmed:
        failures.append(f"{effect} not named and confirmed in either round: " +
                        " | ".join(r.get("fix", {}).get("status", "-")[:80] for r in rounds))
if len(set(confirmed.values())) != len(confirmed):
    failures.append(f"both confirmed in one round? {confirmed}")
for r in rounds[1:]:
    for c in r["fix"].get("candidates", []):
        if "from_earlier_round" not in c:
            failures.append("a round-2 candidate without from_earlier_round")
if confirmed.get("friction") == 1:
    chosen = [c for c in rounds[1]["fix"].get("candidates", []) if c.get("chosen")] if len(rounds) > 1 else []
    print("round 2's tested candidate:", [(c["effect"], c["from_earlier_round"]) for c in chosen])
for f in failures:
    print("FAIL:", f)
if not failures:
    print("ok:", confirmed)
sys.exit(1 if failures else 0)
PY

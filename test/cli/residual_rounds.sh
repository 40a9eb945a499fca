#!/usr/bin/env bash
# `hadynet residual --fix --rounds N` (issue 12): two plant effects at once
# in the seed-1 effect-test logs of docs/residual.md (a 2-step delay of every
# loadcell and a 5x load drift, drift=0.02), declared nowhere. Round 1 must
# confirm the sensor delay and write the model; round 2 analyses round 1's
# change on the network before fine-tuning (a sensor change carries its
# effect alone) on the same raw logs, and its screen must name the drift on
# a loadcell with a rate of at least 0.3 times the plant's 0.02 per (N s):
# a screen on the unchanged network reads a load drift at about 0.42 times
# the plant's (test/residual/fix_margins.h, kDrift), and after round 1's
# fine-tuning, which absorbs much of the drift, it read 0.0031 (0.16 times;
# the rounds before they analysed the change before fine-tuning). Measured
# now: drift-load on fc3, rate 0.0083, confirmation p 0.033, above alpha,
# so it is reported as unexplained structure and the model of round 1 stays
# the written one. (The same with the default five candidates: the sensor
# delay, then the drift, is the first significant on the training rows.)
# Round 2's report goes to DIR/round-2 and the JSON's "rounds". Also:
# --rounds without --fix is a usage error.
# Run with the absolute floors (--reference none) the measurement used; with
# the model's stored null the screen ranks the drift first (docs/residual.md,
# "Rounds").
# About 17 s on the development VM.
#   residual_rounds.sh HADYNET MODEL WORKDIR
set -uo pipefail
hadynet=$1 model=$2 work=$3
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 2
fail() { echo "FAIL: $*"; exit 1; }

for g in "Cylinder random2 1" "Ball random2 2" "Gripper random2 0" "Cylinder random1 0"; do
  set -- $g
  "$hadynet" collect --object "$1" --motion "$2" --init "$3" --rows 300 --seed 1 --out logs \
    --effect sensor-delay --effect drift=0.02 --quiet >/dev/null || fail "collect $g"
done

"$hadynet" residual "$model" logs --rounds 2 >out.txt 2>&1
[[ $? -eq 2 ]] && grep -q -- "--rounds needs --fix" out.txt || fail "--rounds without --fix: $(cat out.txt)"

"$hadynet" residual "$model" logs --reference none --fix --rounds 3 --out fixed.safetensors --report report --json out.json \
  >out.txt 2>&1 || fail "residual --rounds exited $?: $(tail -3 out.txt)"
cat out.txt | grep -E "^verdict:|^fix:|^decision|^rounds|=== round" | cut -c1-140
[[ -s fixed.safetensors ]] || fail "round 1's model not written"
[[ -s report/REPORT.md && -s report/round-2/REPORT.md && -s report/round-2/residual.json ]] ||
  fail "reports of both rounds expected"
python3 - <<'PY' || exit 1
import json, sys
j = json.load(open("out.json"))
first = j["fix"]
rounds = j.get("rounds")
def fail(msg):
    print("FAIL:", msg); sys.exit(1)
if not first["changed"]:
    fail(f"round 1 not confirmed: {first['status']}")
if "time-align" not in first["status"] and "time-align" not in json.dumps(first):
    fail(f"round 1 should fix the sensor delay: {first['status']}")
if not rounds or rounds[0]["round"] != 2:
    fail("the JSON's rounds should hold round 2")
r2 = rounds[0]
if not r2["verdict"].startswith("drift-load: drift on fc"):
    fail(f"round 2 should name the load drift on a loadcell: {r2['verdict']}")
import re
m = re.search(r"rate ([0-9.eE+-]+)", r2["verdict"])
if not m:
    fail(f"round 2's verdict names no drift rate: {r2['verdict']}")
rate = abs(float(m.group(1)))
if rate < 0.3 * 0.02:
    fail(f"round 2 reads the drift at rate {rate:g}, below 0.3 x the plant's 0.02: absorbed by round 1's fine-tuning?")
if "before fine-tuning" not in r2["model"]:
    fail(f"round 2 should analyse round 1's change before fine-tuning, not {r2['model']}")
if r2["fix"]["changed"]:
    # Allowed (a better fine-tune could confirm it), but then the written model must be round 2's.
    if r2["fix"].get("model") != "fixed.safetensors":
        fail("round 2 confirmed but its model was not written")
print("ok: round 1", first["status"][:60], "| round 2", r2["verdict"][:60], "|", r2["fix"]["status"][:40])
PY

#!/usr/bin/env bash
# Issue 12's findings 1 and 3 on the path a user takes: clean logs of the
# four grasps of docs/residual.md recorded with --seed 11 (never used for
# training; the issue's seed), and effects added to them after recording by
# test/cli/inject_effect.py, made by nothing in the plant and declared
# nowhere, then `hadynet residual MODEL LOGS --fix` with the plant's rated
# ranges and every other setting a default (the stored null, --pb auto,
# candidates down to 1, two folds). Before (the issue): the clean logs
# gave a confident cross-talk that --fix applied, none of the added effects
# was named, the clean logs' false positive won four times and the tension
# leak was fixed as a lower rail by clipping.
#
# The cases and their strengths were fixed before the first run and not
# changed after (fresh seeds 1557-1561 with the same cases: docs/residual.md,
# "Effects added after recording"):
#   clean                  nothing confirmed, no model written;
#   delay:fc3:2            one loadcell 2 steps late: its delay, fc3 the winner;
#   drift:f:0.002          every tension drifts with its load at 0.002 /s: a
#                          load drift on tensions, each rate re-estimated
#                          within 0.5-1.5 times 0.002;
#   leak:f5:fc6:0.2        tension f5 leaks into the palm loadcell fc6: the
#                          cross-talk f5 -> fc6, gain within 0.5-1.5 times 0.2;
#   backlash:fc3:1         a 1 N play on one loadcell (a hysteresis of the
#                          sensor; no library effect is one): nothing confirmed;
#   cyclic:l3:0.05:0.5     an encoder's interpolation error on a tendon length
#                          (static, outside the library): nothing confirmed.
# A named effect must also cut its winner's held-out 1-step RMSE to at most
# 0.7 of before and below fine-tuning alone (the benchmarks' rule,
# bench/residual_named.py); the margins are the issue's 30 % cut.
#   residual_injected_effects.sh CASE HADYNET MODEL WORKDIR
set -uo pipefail
case=$1 hadynet=$2 model=$3 work=$4
here=$(cd "$(dirname "$0")/../.." && pwd)
rm -rf "$work" && mkdir -p "$work" || exit 2
source "$here/bench/residual_grasps.sh"
collect_residual_grasps "$hadynet" "$work/raw" 11 || { echo "FAIL: collect"; exit 1; }
if [[ $case == clean ]]; then
  mkdir -p "$work/logs" && find "$work/raw" -name "*.csv" -exec cp {} "$work/logs/" \;
else
  python3 "$here/test/cli/inject_effect.py" "$case" "$work/raw" "$work/logs" || { echo "FAIL: inject $case"; exit 1; }
fi
"$hadynet" residual "$model" "$work/logs" --rated-range fc=0..50 --rated-range f=0..200 --fix \
  --json "$work/residual.json" --out "$work/fixed.safetensors" >"$work/out.txt" 2>&1 \
  || { echo "FAIL: residual"; tail -5 "$work/out.txt"; exit 1; }
python3 - "$case" "$work/residual.json" "$work/fixed.safetensors" <<'PY'
import json, os, re, sys
case, path, fixed = sys.argv[1:]
j = json.load(open(path))
fix = j.get("fix", {})
aug = fix.get("augmentation") or {}
print(f"{case}: screen: {j['verdict'][:120]}")
print(f"{case}: fix: {fix.get('status', '-')[:200]}")
failures = []
def check(ok, what):
    if not ok:
        failures.append(what)
def rmse(part, channel):
    return next(c["rmse"] for c in fix[part]["channels"] if c["channel"] == channel)
def cut(channel):
    before, control, after = rmse("before", channel), rmse("control", channel), rmse("after", channel)
    print(f"{case}: {channel} held-out RMSE before {before:.4g}, fine-tuning alone {control:.4g}, fixed {after:.4g}")
    check(after <= 0.7 * before, f"{channel}: not cut by 30 %")
    check(after < control, f"{channel}: not below fine-tuning alone")

kind = case.split(":")[0]
if kind in ("clean", "backlash", "cyclic"):
    check(not fix.get("changed"), "a fix was confirmed: " + aug.get("description", "")[:120])
    check(not os.path.exists(fixed), "a model was written")
    check(fix.get("status", "").startswith(("no significant effect", "unexplained structure")),
          "status " + fix.get("status", "")[:80])
else:
    check(bool(fix.get("changed")), "nothing confirmed")
    channels = aug.get("channels", [])
    if kind == "delay":
        check(aug.get("effect") == "sensor-delay" and aug.get("delay_steps") == 2, "not a 2-step sensor delay")
        check(channels[:1] == ["fc3"], f"winner {channels[:1]}, not fc3")
    elif kind == "drift":
        check(aug.get("effect") == "drift-load", "not a load drift: " + aug.get("effect", "-"))
        check(bool(channels) and all(re.fullmatch(r"f\d+", c) for c in channels), f"channels {channels}")
        rates = [float(r) for r in re.findall(r"f\d+ ([0-9.eE+-]+)", aug.get("description", "").split("re-estimated:")[-1])]
        print(f"{case}: re-estimated rates {rates}")
        check(len(rates) == len(channels) and all(0.001 <= r <= 0.003 for r in rates), f"rates {rates}")
    elif kind == "leak":
        gain = aug.get("gain", 0.0)
        check(aug.get("effect") == "crosstalk" and channels == ["fc6"] and aug.get("source") == "f5",
              f"not the cross-talk f5 -> fc6: {aug.get('description', '')[:100]}")
        check(0.1 <= gain <= 0.3, f"gain {gain}")
    check(os.path.exists(fixed), "no model written")
    if fix.get("changed") and channels:
        cut(channels[0])
for f in failures:
    print("FAIL:", f)
sys.exit(1 if failures else 0)
PY

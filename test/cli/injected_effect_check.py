#!/usr/bin/env python3
"""Whether `hadynet residual --fix` answered an effect added after recording
(test/cli/inject_effect.py) as it must: residual_injected_effects.sh's rules,
shared with the measurement on fresh seeds (docs/residual-experiments.md, "Effects added
after recording").

usage: injected_effect_check.py CASE RESIDUAL_JSON [MODEL_OUT]

CASE is inject_effect.py's EFFECT, or clean. With MODEL_OUT (the --out of
the run), also whether a model was written exactly when a fix was
confirmed. Prints the outcome; exits 1 when a rule fails.
"""
import json, os, re, sys
if len(sys.argv) == 2 and sys.argv[1] in ("-h", "--help"):
    print(__doc__)
    sys.exit(0)
if len(sys.argv) not in (3, 4):
    sys.exit("usage: injected_effect_check.py CASE RESIDUAL_JSON [MODEL_OUT] (--help)")
case, path = sys.argv[1:3]
fixed = sys.argv[3] if len(sys.argv) == 4 else None
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
    check(fixed is None or not os.path.exists(fixed), "a model was written")
    check(fix.get("status", "").startswith(("no significant effect", "unexplained structure", "not supported")),
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
    else:
        check(False, "no rule for case " + case)
    check(fixed is None or os.path.exists(fixed), "no model written")
    if fix.get("changed") and channels:
        cut(channels[0])
for f in failures:
    print("FAIL:", f)
sys.exit(1 if failures else 0)

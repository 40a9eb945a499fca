#!/usr/bin/env python3
"""bench/residual_ideal_cut.py on sets and twins written here: the ideal cut
(the twin's fine-tuning alone over the set's before, averaged over the
bar's channels, which residual_run_line.cut_channels picks: the decision's
changed channels, not every channel), the unchanged model's, "reachable"
at 0.7 inclusive, the bar's reading beside it, the rail and the curve not
measured, a twin whose --fix fine-tuned nothing, a set with nothing
applied, a twin without a channel refused, and the table. Every expected
number is worked by hand from the values below; the printed ones have two
decimals and none is within 0.001 of a rounding edge, so the strings are
exact."""
import copy
import json
import os
import subprocess
import sys
import tempfile

SCRIPT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "bench", "residual_ideal_cut.py")
failures = []


def check(ok, what):
    if not ok:
        failures.append(what)
        print("FAIL:", what)


def rmse(values):
    return {"channels": [{"channel": c, "rmse": v} for c, v in values.items()]}


def write_json(path, fix):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "w") as f:
        json.dump({"fix": fix}, f)


def run(*args):
    return subprocess.run([sys.executable, SCRIPT, *args], capture_output=True, text=True)


# The set: the tension leak into fc6 (the bench's rule names it), judged on
# fc6 and fc5; its plan changes fc6 alone, so the bar reads fc6: cut
# 0.12 / 0.4 = 0.30, after 0.12 below the control's 0.3.
LEAK = {
    "train_fraction": 0.6, "changed": True,
    "augmentation": {"effect": "crosstalk", "channels": ["fc6"], "source": "f5", "gain": 0.2,
                     "description": "remove the crosstalk f5 -> fc6"},
    "confirmation": {"channels": ["fc5", "fc6"]},
    "before": rmse({"fc0": 0.4, "fc5": 0.5, "fc6": 0.4}),
    "after": rmse({"fc0": 0.4, "fc5": 0.3, "fc6": 0.12}),
    "control": rmse({"fc0": 0.4, "fc5": 0.5, "fc6": 0.3}),
}
# The twin: fine-tuning alone reads fc6 at 0.1 (0.1 / 0.4 = 0.25); the
# unchanged model 0.14 (0.35). fc5's 0.054 must not count (not changed).
TWIN = {
    "changed": False,
    "before": rmse({"fc0": 0.3, "fc5": 0.054, "fc6": 0.14}),
    "control": rmse({"fc0": 0.2, "fc5": 0.054, "fc6": 0.1}),
}


def line_of(tmp, name, fix, twin, case="tension-leak=0.2", seed="7"):
    write_json(os.path.join(tmp, name, "residual.json"), fix)
    write_json(os.path.join(tmp, name + ".twin.json"), twin)
    return run("line", case, seed, os.path.join(tmp, name), os.path.join(tmp, name + ".twin.json"))


def main():
    with tempfile.TemporaryDirectory() as tmp:
        r = line_of(tmp, "pass", LEAK, TWIN)
        expected = ("tension-leak=0.2 seed 7: bar yes named yes cut yes 0.30 ideal 0.25 (unchanged model 0.35) "
                    "reachable yes (on 1 channels)")
        check(r.returncode == 0 and r.stdout.strip() == expected, f"reachable: {r.stdout!r} {r.stderr!r}")
        lines = [r.stdout]

        # Two changed channels: fc5 joins the plan (so the leak is not named:
        # the bench's rule asks for fc6 alone). Ideal (0.054 / 0.5 + 0.1 /
        # 0.4) / 2 = 0.179; the unchanged model (0.108 + 0.35) / 2 = 0.229;
        # the bar's cut (0.6 + 0.3) / 2 = 0.45, not an edge: the script's
        # rounding of 0.45 is residual_run_line's, read from its line.
        fix = copy.deepcopy(LEAK)
        fix["augmentation"]["channels"] = ["fc5", "fc6"]
        r = line_of(tmp, "two", fix, TWIN, seed="8")
        check(r.stdout.strip().startswith("tension-leak=0.2 seed 8: bar no  named no  cut yes 0.45 ideal 0.18 "
              "(unchanged model 0.23) reachable yes (on 2 channels)"), f"two channels: {r.stdout!r}")

        # Out of reach: the twin's fine-tuning reads fc6 at 0.32 (0.80), and
        # the fix is short too (after 0.3: 0.75), named: "named, cut short,
        # ideal above 0.7" in the table.
        fix = copy.deepcopy(LEAK)
        fix["after"] = rmse({"fc0": 0.4, "fc5": 0.3, "fc6": 0.3})
        fix["control"] = rmse({"fc0": 0.4, "fc5": 0.5, "fc6": 0.35})
        twin = copy.deepcopy(TWIN)
        twin["control"] = rmse({"fc0": 0.2, "fc5": 0.05, "fc6": 0.32})
        r = line_of(tmp, "out", fix, twin, seed="9")
        check(r.stdout.strip() == "tension-leak=0.2 seed 9: bar no  named yes cut no  0.75 ideal 0.80 "
              "(unchanged model 0.35) reachable no  (on 1 channels)", f"out of reach: {r.stdout!r}")
        lines.append(r.stdout)

        # The bar's cut just above 0.7 prints as 0.70 (0.2802 / 0.4 = 0.7005)
        # and is short: the flag is the bar's, not read back from the print.
        fix = copy.deepcopy(LEAK)
        fix["after"] = rmse({"fc0": 0.4, "fc5": 0.3, "fc6": 0.2802})
        r = line_of(tmp, "just_short", fix, TWIN, seed="16")
        check(r.stdout.startswith("tension-leak=0.2 seed 16: bar no  named yes cut no  0.70 ideal 0.25"),
              f"just short of the cut: {r.stdout!r}")
        lines.append(r.stdout)

        # At 0.7 (0.35 / 0.5 on fc5 alone: the double nearest 0.35, halved
        # exactly, is the double nearest 0.7) it is reachable.
        fix = copy.deepcopy(LEAK)
        fix["augmentation"]["channels"] = ["fc5"]
        fix["before"] = rmse({"fc0": 0.4, "fc5": 0.5, "fc6": 0.4})
        twin = copy.deepcopy(TWIN)
        twin["control"] = rmse({"fc0": 0.2, "fc5": 0.35, "fc6": 0.1})
        r = line_of(tmp, "edge", fix, twin, seed="10")
        check("ideal 0.70" in r.stdout and "reachable yes" in r.stdout, f"0.7 counts as reachable: {r.stdout!r}")

        # Not named (the plan on fc5 and fc6 with the leak found on fc5 alone
        # is still named here; a cross-talk of another source is not).
        fix = copy.deepcopy(LEAK)
        fix["augmentation"]["source"] = "f4"
        fix["augmentation"]["description"] = "remove the crosstalk f4 -> fc6"
        r = line_of(tmp, "unnamed", fix, TWIN, seed="11")
        check(r.stdout.startswith("tension-leak=0.2 seed 11: bar no  named no  cut yes 0.30 ideal 0.25"),
              f"not named: {r.stdout!r}")
        lines.append(r.stdout)

        # The rail and the curve: not measured, whatever the numbers.
        for case in ("saturation=2", "sensor-curve=0.7"):
            r = line_of(tmp, "rail", LEAK, TWIN, case=case, seed="12")
            check(r.returncode == 0 and "not measured (the effect changes the readings' scale" in r.stdout
                  and "ideal" not in r.stdout, f"{case} not measured: {r.stdout!r}")
            lines.append(r.stdout)

        # A twin whose --fix tried nothing (no control): not measured.
        twin = {k: v for k, v in TWIN.items() if k != "control"}
        r = line_of(tmp, "no_control", LEAK, twin, seed="13")
        check(r.returncode == 0 and "not measured (the twin's --fix tried nothing" in r.stdout,
              f"twin without control: {r.stdout!r}")

        # Nothing applied: a line that says so.
        fix = {k: v for k, v in LEAK.items() if k not in ("after", "control", "confirmation")}
        fix["changed"] = False
        r = line_of(tmp, "nothing", fix, TWIN, seed="14")
        check(r.returncode == 0 and r.stdout.strip() == "tension-leak=0.2 seed 14: bar no  named no  "
              "(nothing applied)", f"nothing applied: {r.stdout!r}")

        # A twin without the set's channel is refused with its name.
        twin = copy.deepcopy(TWIN)
        twin["control"] = rmse({"fc0": 0.2, "fc5": 0.05})
        r = line_of(tmp, "missing", LEAK, twin, seed="15")
        check(r.returncode != 0 and "has no channel fc6" in r.stderr, f"twin missing fc6: {r.stdout!r} {r.stderr!r}")

        # The table: four leak sets read (7 reachable and passed, 9 short
        # and out of reach, 11 not named, 16 short and reachable), the rail
        # and the curve left out.
        path = os.path.join(tmp, "lines.txt")
        with open(path, "w") as f:
            f.write("".join(lines))
        r = run("table", path)
        check(r.returncode == 0 and "| tension-leak=0.2 | 4 | 1 | 2 | 1 (9) | 1 | 0.25 |" in r.stdout
              and "saturation" not in r.stdout and "sensor-curve" not in r.stdout, f"table: {r.stdout!r}")

        r = run("--help")
        check(r.returncode == 0 and "ideal cut" in r.stdout, "--help")
        r = run("line", "x")
        check(r.returncode == 2, "bad arguments exit 2")
    if failures:
        print(f"{len(failures)} check(s) failed")
        sys.exit(1)
    print("all checks passed")


if __name__ == "__main__":
    main()

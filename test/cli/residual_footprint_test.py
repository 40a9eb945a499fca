#!/usr/bin/env python3
"""bench/residual_footprint.py on sets written here: which channels count as
moved (the footprint's RMS on the held-out rows against the share of the
channel's error before, the share itself counting), the cut (at most 0.7)
and the control read on them whether or not the plan changed them, the
bar's reading beside it (named, cut and control), drift refused, a set with
nothing applied, a twin that does not match refused, a bad --share, and
the table. Every expected number is worked by hand from the values below;
the printed ones have two decimals and none is within 0.001 of a rounding
edge, so the strings are exact. The footprints are exact in binary (0.25,
and 0.3 or 0.1 against a clean 1.0..4.0) or compared far from the share."""
import copy
import json
import os
import subprocess
import sys
import tempfile

SCRIPT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "bench", "residual_footprint.py")
failures = []


def check(ok, what):
    if not ok:
        failures.append(what)
        print("FAIL:", what)


def write_log(path, columns, rows):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "w") as f:
        f.write("# a comment line the reader skips\n")
        f.write(",".join(columns) + "\n")
        for r in rows:
            f.write(",".join(repr(v) for v in r) + "\n")


def rmse(values):
    return {"channels": [{"channel": c, "rmse": v} for c, v in values.items()]}


def write_set(root, fix):
    os.makedirs(root, exist_ok=True)
    with open(os.path.join(root, "residual.json"), "w") as f:
        json.dump({"fix": fix}, f)


def run(*args):
    return subprocess.run([sys.executable, SCRIPT, *args], capture_output=True, text=True)


# The logs: two of 10 rows, held-out rows 6..9 (train_fraction 0.6). The
# effect adds 0.3 to fc6 on every held-out row (footprint 0.3), 0.1 to fc5
# (0.1), 0.25 to fc2 (0.25) and 0.3 to fc1 on log a's held-out rows only
# (RMS over both logs' 8 rows: sqrt(4 * 0.09 / 8) = 0.212); fc0 is left
# alone. Before the held-out rows fc5 and fc6 differ by 5, which must not
# count.
COLUMNS = ["t", "fc0", "fc1", "fc2", "fc5", "fc6"]


def write_logs(tmp):
    for name, fc1_shift in (("a.csv", 0.3), ("b.csv", 0.0)):
        clean = [[0.2 * t, 1.0, 2.0, 1.0, 3.0, 4.0] for t in range(10)]
        effect = [list(r) for r in clean]
        for t in range(10):
            held_out = t >= 6
            effect[t][2] += fc1_shift if held_out else 0.0
            effect[t][3] = 1.25 if held_out else 1.0
            effect[t][4] += 0.1 if held_out else 5.0
            effect[t][5] += 0.3 if held_out else 5.0
        write_log(os.path.join(tmp, "logs", "train", name), COLUMNS, effect)
        write_log(os.path.join(tmp, "clean", "train", name), COLUMNS, clean)


# The plan: the tension leak into fc6, which the bench's rule names. Before:
# 0.4 on every channel but fc2 (0.5). So fc1 (0.212 / 0.4 = 0.53), fc2
# (0.25 / 0.5 = 0.50, at the share exactly) and fc6 (0.75) are moved; fc5
# (0.25) and fc0 (0) are not.
LEAK = {
    "train_fraction": 0.6, "changed": True,
    "augmentation": {"effect": "crosstalk", "channels": ["fc6"], "source": "f5", "gain": 0.2,
                     "description": "remove the crosstalk f5 -> fc6"},
    "confirmation": {"channels": ["fc6"]},
    "before": rmse({"fc0": 0.4, "fc1": 0.4, "fc2": 0.5, "fc5": 0.4, "fc6": 0.4}),
    "after": rmse({"fc0": 0.4, "fc1": 0.3, "fc2": 0.35, "fc5": 0.2, "fc6": 0.12}),
    "control": rmse({"fc0": 0.4, "fc1": 0.4, "fc2": 0.5, "fc5": 0.4, "fc6": 0.3}),
}


def line_of(tmp, name, fix, case="tension-leak=0.2", seed="7", *extra):
    root = os.path.join(tmp, name)
    write_set(root, fix)
    os.makedirs(root, exist_ok=True)
    if not os.path.exists(os.path.join(root, "logs")):
        os.symlink(os.path.join(tmp, "logs"), os.path.join(root, "logs"))
    return run("line", case, seed, root, os.path.join(tmp, "clean"), *extra)


def main():
    with tempfile.TemporaryDirectory() as tmp:
        write_logs(tmp)

        # Both pass. The cut on fc1, fc2, fc6: (0.75 + 0.7 + 0.3) / 3 = 0.583;
        # after 0.77 against the control's 1.2 there. The bar's cut, fc6: 0.30.
        r = line_of(tmp, "pass", LEAK)
        expected = ("tension-leak=0.2 seed 7: bar yes moved yes named yes (moved fc1(0.53) fc2(0.50) fc6(0.75); "
                    "cut there 0.58, below the control there yes; the bar's cut 0.30)")
        check(r.returncode == 0 and r.stdout.strip() == expected, f"both pass: {r.stdout!r} {r.stderr!r}")

        # At a share of 0.6, fc1 (0.53) and fc2 (0.50) are not moved: fc6 alone, cut 0.30.
        r = line_of(tmp, "pass", LEAK, "tension-leak=0.2", "7", "--share", "0.6")
        check("(moved fc6(0.75); cut there 0.30, below" in r.stdout, f"share 0.6: {r.stdout!r}")

        # The cut on the moved channels above 0.7, the bar's not: fc2 after
        # 0.5 and fc1 after 0.4 give (1 + 1 + 0.3) / 3 = 0.767.
        fix = copy.deepcopy(LEAK)
        fix["after"] = rmse({"fc0": 0.4, "fc1": 0.4, "fc2": 0.5, "fc5": 0.2, "fc6": 0.12})
        r = line_of(tmp, "short", fix)
        check(r.stdout.startswith("tension-leak=0.2 seed 7: bar yes moved no  named yes")
              and "cut there 0.77, below the control there yes" in r.stdout, f"short on the moved: {r.stdout!r}")

        # The bar's cut above 0.7 (fc6 after 0.32: 0.80), the moved one not
        # (fc1 0.1, fc2 0.1: (0.25 + 0.2 + 0.8) / 3 = 0.417): the bar fails.
        fix = copy.deepcopy(LEAK)
        fix["after"] = rmse({"fc0": 0.4, "fc1": 0.1, "fc2": 0.1, "fc5": 0.2, "fc6": 0.32})
        r = line_of(tmp, "bar_short", fix)
        check(r.stdout.startswith("tension-leak=0.2 seed 7: bar no  moved yes named yes")
              and "cut there 0.42" in r.stdout and "the bar's cut 0.80)" in r.stdout, f"short on the plan's: {r.stdout!r}")

        # The control below the fix on the moved channels (fc1 0.1, fc2 0.1:
        # 0.5 against 0.77) fails the moved reading alone.
        fix = copy.deepcopy(LEAK)
        fix["control"] = rmse({"fc0": 0.4, "fc1": 0.1, "fc2": 0.1, "fc5": 0.4, "fc6": 0.3})
        r = line_of(tmp, "control", fix)
        check(r.stdout.startswith("tension-leak=0.2 seed 7: bar yes moved no  named yes")
              and "below the control there no" in r.stdout, f"the control on the moved: {r.stdout!r}")

        # Not named (the leak found on fc5): neither reading passes, whatever the cut.
        fix = copy.deepcopy(LEAK)
        fix["augmentation"]["channels"] = ["fc5"]
        fix["confirmation"]["channels"] = ["fc5"]
        r = line_of(tmp, "unnamed", fix)
        check(r.stdout.startswith("tension-leak=0.2 seed 7: bar no  moved no  named no "), f"not named: {r.stdout!r}")

        # Nothing applied (no "after"; not confirmed, so not named): a line that says so.
        fix = {k: v for k, v in LEAK.items() if k not in ("after", "control", "confirmation")}
        fix["changed"] = False
        r = line_of(tmp, "nothing", fix)
        check(r.returncode == 0 and r.stdout.strip() == "tension-leak=0.2 seed 7: bar no  moved no  named no  "
              "(nothing applied)", f"nothing applied: {r.stdout!r}")

        # Drift has no clean twin (its walk shares the noise's generator).
        r = line_of(tmp, "pass", LEAK, "drift=0.02", "9")
        check(r.returncode == 0 and "not measured" in r.stdout, f"drift: {r.stdout!r}")

        # A bad --share: exit 2 with a message.
        for bad in (["--share"], ["--share", "x"], ["--share", "0"]):
            r = line_of(tmp, "pass", LEAK, "tension-leak=0.2", "7", *bad)
            check(r.returncode == 2 and "--share" in r.stderr, f"--share {bad[1:]}: {r.returncode} {r.stderr!r}")

        # A twin with a row less, then with a log missing, is refused.
        clean_a = os.path.join(tmp, "clean", "train", "a.csv")
        with open(clean_a) as f:
            text = f.read()
        with open(clean_a, "w") as f:
            f.write(text[:text.rstrip("\n").rfind("\n") + 1])
        r = line_of(tmp, "pass", LEAK)
        check(r.returncode != 0 and "rows differ" in r.stderr, f"a row less: {r.stderr!r}")
        os.remove(clean_a)
        r = line_of(tmp, "pass", LEAK)
        check(r.returncode != 0 and "do not hold the same logs" in r.stderr, f"a missing twin log: {r.stderr!r}")

        # The table: per case, the bar's passes and the moved reading's, and
        # the sets passing one and not the other; drift's lines left out.
        lines = os.path.join(tmp, "lines.txt")
        with open(lines, "w") as f:
            f.write("tension-leak=0.2 seed 7: bar yes moved yes named yes (x)\n")
            f.write("tension-leak=0.2 seed 8: bar yes moved no  named yes (x)\n")
            f.write("friction=4 seed 1: bar no  moved yes named yes (x)\n")
            f.write("drift=0.02 seed 9: not measured (x)\n")
        r = run("table", lines)
        check("| friction=4 | 1 | 0 | 1 | - | 1 |" in r.stdout, f"table, friction: {r.stdout!r}")
        check("| tension-leak=0.2 | 2 | 2 | 1 | 8 | - |" in r.stdout, f"table, leak: {r.stdout!r}")
        check("| all | 3 | 2 | 2 |" in r.stdout and "drift" not in r.stdout, f"table, total: {r.stdout!r}")

        check(run("--help").returncode == 0 and run().returncode == 2, "--help exits 0, no arguments 2")
    if failures:
        sys.exit(1)
    print("residual_footprint: all checks passed")


if __name__ == "__main__":
    main()

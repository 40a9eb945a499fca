#!/usr/bin/env python3
"""bench/residual_footprint.py on a set written here: which channels count as
moved (the footprint's RMS on the held-out rows against half the channel's
error before), the cut and the control read on them whether or not the
plan changed them, the bar's reading beside it, drift refused, and the
table. Every expected number is worked by hand from the values below; the
printed ones have two decimals and none is within 0.001 of a rounding
edge, so the strings are exact."""
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


def run(*args):
    return subprocess.run([sys.executable, SCRIPT, *args], capture_output=True, text=True)


def main():
    with tempfile.TemporaryDirectory() as tmp:
        # Two logs of 10 rows, held-out rows 6..9 (train_fraction 0.6).
        # The effect adds 0.3 to fc6 on every held-out row (footprint 0.3,
        # before 0.4: moved), 0.1 to fc5 (0.1 against 0.4: not moved), and
        # 0.3 to fc1 on one log's held-out rows only (RMS over both logs'
        # 8 rows: sqrt(4 * 0.09 / 8) = 0.212 against before 0.4: moved);
        # fc0 is left alone. Values before the held-out rows differ too and
        # must not count.
        columns = ["t", "fc0", "fc1", "fc5", "fc6"]
        for name, fc1_shift in (("a.csv", 0.3), ("b.csv", 0.0)):
            clean = [[0.2 * t, 1.0, 2.0, 3.0, 4.0] for t in range(10)]
            effect = [list(r) for r in clean]
            for t in range(10):
                held_out = t >= 6
                effect[t][4] += 0.3 if held_out else 5.0
                effect[t][3] += 0.1 if held_out else 5.0
                effect[t][2] += fc1_shift if held_out else 0.0
            write_log(os.path.join(tmp, "set", "logs", "train", name), columns, effect)
            write_log(os.path.join(tmp, "clean", "train", name), columns, clean)
        # The plan: the leak into fc6 (named by the rule); fc1 moved and not
        # in the plan. before 0.4 everywhere; after fc6 0.12, fc1 0.4, fc5
        # 0.2; control fc6 0.3, fc1 0.3.
        fix = {
            "train_fraction": 0.6, "changed": True,
            "augmentation": {"effect": "crosstalk", "channels": ["fc6"], "source": "f5", "gain": 0.2,
                             "description": "remove the crosstalk f5 -> fc6"},
            "confirmation": {"channels": ["fc6"]},
            "before": {"channels": [{"channel": c, "rmse": 0.4} for c in ("fc0", "fc1", "fc5", "fc6")]},
            "after": {"channels": [{"channel": "fc0", "rmse": 0.4}, {"channel": "fc1", "rmse": 0.4},
                                   {"channel": "fc5", "rmse": 0.2}, {"channel": "fc6", "rmse": 0.12}]},
            "control": {"channels": [{"channel": "fc0", "rmse": 0.4}, {"channel": "fc1", "rmse": 0.3},
                                     {"channel": "fc5", "rmse": 0.4}, {"channel": "fc6", "rmse": 0.3}]},
        }
        with open(os.path.join(tmp, "set", "residual.json"), "w") as f:
            json.dump({"fix": fix}, f)
        set_dir, clean_dir = os.path.join(tmp, "set"), os.path.join(tmp, "clean")

        # Moved: fc1 (0.53 of its error) and fc6 (0.75). The cut there:
        # (0.4/0.4 + 0.12/0.4) / 2 = 0.65 <= 0.7; after 0.52 against the
        # control's 0.6 there: passes. The bar's cut on fc6 alone: 0.30.
        r = run("line", "tension-leak=0.2", "7", set_dir, clean_dir)
        expected = ("tension-leak=0.2 seed 7: bar yes moved yes named yes (moved fc1(0.53) fc6(0.75); "
                    "cut there 0.65, below the control there yes; the bar's cut 0.30)")
        check(r.returncode == 0 and r.stdout.strip() == expected, f"line at the default share: {r.stdout!r} {r.stderr!r}")

        # At a share of 0.6, fc1 (0.53) is no longer moved: fc6 alone, cut 0.30.
        r = run("line", "tension-leak=0.2", "7", set_dir, clean_dir, "--share", "0.6")
        check("(moved fc6(0.75); cut there 0.30, below the control there yes" in r.stdout,
              f"line at share 0.6: {r.stdout!r}")

        # A control below the fix on the moved channels fails the moved
        # reading and not the bar's: the control's fc1 at 0.1 (sum 0.4
        # against after's 0.52), fc6 unchanged.
        fix["control"]["channels"][1]["rmse"] = 0.1
        with open(os.path.join(set_dir, "residual.json"), "w") as f:
            json.dump({"fix": fix}, f)
        r = run("line", "tension-leak=0.2", "8", set_dir, clean_dir)
        check(r.stdout.startswith("tension-leak=0.2 seed 8: bar yes moved no  named yes")
              and "below the control there no" in r.stdout, f"the control on the moved channels: {r.stdout!r}")

        # Drift has no clean twin (its walk shares the noise's generator).
        r = run("line", "drift=0.02", "9", set_dir, clean_dir)
        check(r.returncode == 0 and "not measured" in r.stdout, f"drift: {r.stdout!r}")

        # A twin with other logs is refused.
        os.remove(os.path.join(clean_dir, "train", "b.csv"))
        r = run("line", "tension-leak=0.2", "7", set_dir, clean_dir)
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

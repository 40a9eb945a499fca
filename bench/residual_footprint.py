#!/usr/bin/env python3
"""Issue 12's detection bar with its cut read on the channels the plant's
effect moved (a diagnostic beside bench/residual_run_line.py; not a test,
not the bar).

  residual_footprint.py line CASE SEED SET_DIR CLEAN_DIR [--share X]
  residual_footprint.py table LINES_FILE

line: SET_DIR is one set of bench/residual_detection.sh (SET_DIR/logs with
the effect switched on, SET_DIR/residual.json); CLEAN_DIR the same seed's
grasps recorded without the effect (bench/residual_grasps.sh, same rows).
The plant draws the same noise with and without an effect, so a log's
difference from its clean twin is the effect's footprint (a channel the
effect leaves alone differs by exactly 0). Not for drift: the plant's
drift includes a random walk drawn from the sensor noise's generator
(host-sim/plant/sensor_simulation.cc), so the twins' noise differs on
every channel; its line says so and the table leaves it out. A channel is
**moved** when the RMS of that difference over the held-out rows (each
log's last 1 - train_fraction, the rows residual.json's before/after are
measured on) is at least X of the channel's held-out 1-step RMSE before
the fix (--share X, 0.5: fixed after one development set, the rail 4951,
and before any other set was read). Prints one line:

  CASE seed SEED: bar yes|no moved yes|no named yes|no (moved CH(SHARE)
  ...; cut there R, below the control there yes|no; the bar's cut R0)

  bar    the bar's rule as residual_run_line.py reads it (named, the mean
         after/before on the changed channels <= 0.7, below the control);
  moved  the same, with the cut and the control read on the moved channels
         (every moved channel, whether or not the plan changed it);
  SHARE  the channel's footprint over its error before.
A set with nothing applied says so and passes neither.

table: per case, sets, passed by the bar, passed on the moved channels, and
the sets that pass one reading and not the other.
"""
import csv
import json
import math
import os
import re
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from residual_run_line import rmse_of, run_line  # noqa: E402


def read_log(path):
    """(column names, rows of floats) of a log (comment lines start with #)."""
    with open(path) as f:
        rows = list(csv.reader(line for line in f if not line.startswith("#")))
    return rows[0], [[float(v) for v in r] for r in rows[1:]]


def log_files(directory):
    """{file name: path} of the .csv logs under `directory` (recursively)."""
    out = {}
    for root, _, files in os.walk(directory):
        for name in files:
            if name.endswith(".csv"):
                if name in out:
                    sys.exit(f"residual_footprint: two logs named {name} under {directory}")
                out[name] = os.path.join(root, name)
    return out


def footprint(set_logs, clean_logs, train_fraction):
    """{channel: RMS of (effect - clean)} over each log's held-out rows."""
    effect, clean = log_files(set_logs), log_files(clean_logs)
    if sorted(effect) != sorted(clean) or not effect:
        sys.exit(f"residual_footprint: {set_logs} and {clean_logs} do not hold the same logs")
    sums, counts = {}, {}
    for name in sorted(effect):
        head, rows = read_log(effect[name])
        clean_head, clean_rows = read_log(clean[name])
        if head != clean_head or len(rows) != len(clean_rows):
            sys.exit(f"residual_footprint: {name}: columns or rows differ from its clean twin")
        first = int(train_fraction * len(rows))
        for j, channel in enumerate(head):
            d = [rows[t][j] - clean_rows[t][j] for t in range(first, len(rows))]
            sums[channel] = sums.get(channel, 0.0) + sum(v * v for v in d)
            counts[channel] = counts.get(channel, 0) + len(d)
    return {c: math.sqrt(sums[c] / counts[c]) for c in sums if counts[c]}


def line(case, seed, set_dir, clean_dir, share):
    bar_line = run_line(case, seed, os.path.join(set_dir, "residual.json"), "")
    m = re.match(r"\S+ seed \d+: named (yes|no) +cut (yes|no) +\(after/before (\S+)\) <control (yes|no)", bar_line)
    if not m:
        sys.exit(f"residual_footprint: residual_run_line.py's line is not in the form read here: {bar_line}")
    named = m.group(1) == "yes"
    bar = named and m.group(2) == "yes" and m.group(4) == "yes"
    fix = json.load(open(os.path.join(set_dir, "residual.json")))["fix"]
    out = f"{case} seed {seed}: "
    if case.startswith("drift="):
        return out + "not measured (the drift's walk draws from the sensor noise's generator: no clean twin)"
    if not (fix.get("before") and fix.get("after")):
        return out + f"bar no  moved no  named {'yes' if named else 'no '} (nothing applied)"

    before, after = rmse_of(fix, "before"), rmse_of(fix, "after")
    control = rmse_of(fix, "control") if fix.get("control") else {}
    moved_by = footprint(os.path.join(set_dir, "logs"), clean_dir, fix["train_fraction"])
    moved = [c for c in before if moved_by.get(c, 0.0) >= share * before[c]]
    ratio = sum(after[c] / before[c] for c in moved) / len(moved) if moved else float("nan")
    below = bool(control) and bool(moved) and sum(after[c] for c in moved) < sum(control[c] for c in moved)
    passed = named and ratio <= 0.7 and below
    shares = " ".join(f"{c}({moved_by[c] / before[c]:.2f})" for c in moved)
    return (out + f"bar {'yes' if bar else 'no '} moved {'yes' if passed else 'no '} named {'yes' if named else 'no '} "
            f"(moved {shares or '-'}; cut there {ratio:.2f}, below the control there {'yes' if below else 'no'}; "
            f"the bar's cut {m.group(3)})")


def table(path):
    rows = {}
    for text in open(path):
        m = re.match(r"(\S+) seed (\d+): bar (yes|no) +moved (yes|no)", text)
        if not m:
            continue
        r = rows.setdefault(m.group(1), [0, 0, 0, [], []])
        bar, moved = m.group(3) == "yes", m.group(4) == "yes"
        r[0] += 1
        r[1] += bar
        r[2] += moved
        if bar and not moved:
            r[3].append(m.group(2))
        if moved and not bar:
            r[4].append(m.group(2))
    out = ["| case | sets | passed, the bar | passed, cut on the moved channels | bar only | moved only |",
           "|---|---|---|---|---|---|"]
    total = [0, 0, 0]
    for case in sorted(rows):
        r = rows[case]
        total = [total[0] + r[0], total[1] + r[1], total[2] + r[2]]
        out.append(f"| {case} | {r[0]} | {r[1]} | {r[2]} | {', '.join(r[3]) or '-'} | {', '.join(r[4]) or '-'} |")
    out.append(f"| all | {total[0]} | {total[1]} | {total[2]} | | |")
    return "\n".join(out)


if __name__ == "__main__":
    args = sys.argv[1:]
    if args in (["-h"], ["--help"]):
        print(__doc__)
        sys.exit(0)
    share = 0.5
    if "--share" in args:
        k = args.index("--share")
        try:
            share = float(args[k + 1])
        except (IndexError, ValueError):
            share = -1.0
        if not share > 0:
            print("residual_footprint: --share needs a number above 0", file=sys.stderr)
            sys.exit(2)
        del args[k:k + 2]
    if len(args) == 5 and args[0] == "line":
        print(line(args[1], int(args[2]), args[3], args[4], share))
    elif len(args) == 2 and args[0] == "table":
        print(table(args[1]))
    else:
        print(__doc__, file=sys.stderr)
        sys.exit(2)

#!/usr/bin/env python3
"""Summary of bench/device_adaptation.sh: the firmware's PB adaptation (q15,
f32) against the trainer's online adaptation on the same streams.

Usage: device_adaptation_summary.py --tag TAG INIT_DIR...
Each INIT_DIR holds TAG/<name>.q15.csv, TAG/<name>.f32.csv (hadynet replay
--adapt) and trainer/<name>.csv (hadynet adapt --online), <name> one of the
six objects or "switch" (None -> Cylinder -> Cylinder-L)."""
import argparse
import csv
import math
import os
import statistics
import sys

OBJECTS = ["None", "Hammer", "Hammer-S", "Cylinder", "Gripper", "Ball"]
PERIOD_S = 0.2


def object_of(state):
    return state.split("/")[0] if state else ""


def read_device(path):
    """Rows of a replay CSV: (log index, row in log, pb list, recognized state)."""
    rows, count = [], {}
    with open(path) as f:
        r = csv.DictReader(f)
        pb_cols = [c for c in r.fieldnames if c.startswith("pb_")]
        for row in r:
            log = int(row["log"])
            t = count.get(log, 0)
            count[log] = t + 1
            rows.append((log, t, [float(row[c]) for c in pb_cols], row["recognized"]))
    return rows


def read_trainer(path, log_names):
    """{(log index, row): (pb, nearest)} of a `hadynet adapt --online` CSV."""
    out = {}
    with open(path) as f:
        r = csv.DictReader(f)
        pb_cols = [c for c in r.fieldnames if c.startswith("p") and c[1:].isdigit()]
        for row in r:
            log = log_names.index(row["log"]) if row["log"] in log_names else 0
            out[(log, int(row["t_step"]))] = ([float(row[c]) for c in pb_cols], row["nearest"])
    return out


def trainer_logs(path):
    names = []
    with open(path) as f:
        for row in csv.DictReader(f):
            if row["log"] not in names:
                names.append(row["log"])
    return names


def dist(a, b):
    return math.sqrt(sum((x - y) ** 2 for x, y in zip(a, b)))


def last_label(rows, log):
    seg = [r for r in rows if r[0] == log]
    return object_of(seg[-1][3]) if seg else ""


def periods_to_follow(labels, want):
    """Periods from the segment's start until the label is `want` for good (None: never)."""
    for k in range(len(labels) - 1, -1, -1):
        if labels[k] != want:
            return None if k == len(labels) - 1 else k + 1
    return 0


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--tag", required=True)
    ap.add_argument("dirs", nargs="+")
    a = ap.parse_args()

    right = {"q15": 0, "f32": 0, "trainer": 0}
    agree_q_t = agree_q_f = n = 0
    end_dt, end_qf, med_dt = [], [], []
    per_object = {o: {"q15": 0, "trainer": 0, "n": 0} for o in OBJECTS}
    follow = {"q15": [], "trainer": []}
    cyl_l = {"q15": [], "trainer": []}
    for d in a.dirs:
        for o in OBJECTS:
            q = read_device(os.path.join(d, a.tag, f"{o}.q15.csv"))
            f = read_device(os.path.join(d, a.tag, f"{o}.f32.csv"))
            tpath = os.path.join(d, "trainer", f"{o}.csv")
            t = read_trainer(tpath, trainer_logs(tpath))
            lq, lf = last_label(q, 0), last_label(f, 0)
            last_t = max(t) if t else None
            lt = object_of(t[last_t][1]) if last_t else ""
            n += 1
            per_object[o]["n"] += 1
            for k, lab in (("q15", lq), ("f32", lf), ("trainer", lt)):
                right[k] += lab == o
            per_object[o]["q15"] += lq == o
            per_object[o]["trainer"] += lt == o
            agree_q_t += lq == lt
            agree_q_f += lq == lf
            if last_t:
                end_dt.append(dist(f[-1][2], t[last_t][0]))
                dts = [dist(r[2], t[(r[0], r[1])][0]) for r in f if (r[0], r[1]) in t]
                med_dt.append(statistics.median(dts))
            end_qf.append(dist(q[-1][2], f[-1][2]))
        # The switching stream.
        q = read_device(os.path.join(d, a.tag, "switch.q15.csv"))
        tpath = os.path.join(d, "trainer", "switch.csv")
        names = trainer_logs(tpath)
        t = read_trainer(tpath, names)
        labels_q = [object_of(r[3]) for r in q if r[0] == 1]
        rows_1 = [r[1] for r in q if r[0] == 1]
        labels_t = [object_of(t[(1, k)][1]) if (1, k) in t else "" for k in rows_1]
        follow["q15"].append(periods_to_follow(labels_q, "Cylinder"))
        follow["trainer"].append(periods_to_follow(labels_t, "Cylinder"))
        cyl_l["q15"].append(last_label(q, 2))
        last2 = max((k for k in t if k[0] == 2), default=None)
        cyl_l["trainer"].append(object_of(t[last2][1]) if last2 else "")

    print(f"device adaptation ({a.tag}) over {len(a.dirs)} zeroings, {n} single-object streams of 500 rows")
    print("object named right at the end of its stream: "
          + ", ".join(f"{k} {v}/{n} ({100.0 * v / n:.1f} %)" for k, v in right.items()))
    print(f"device q15 names the trainer's object: {agree_q_t}/{n} ({100.0 * agree_q_t / n:.1f} %); "
          f"q15 names f32's: {agree_q_f}/{n}")
    print("per object (q15 / trainer right): "
          + ", ".join(f"{o} {v['q15']}/{v['trainer']} of {v['n']}" for o, v in per_object.items()))
    if end_dt:
        print(f"PB distance f32 device - trainer: median over rows {statistics.median(med_dt):.3f}, "
              f"at the end median {statistics.median(end_dt):.3f} max {max(end_dt):.3f}")
    print(f"PB distance q15 - f32 at the end: median {statistics.median(end_qf):.4f} max {max(end_qf):.4f}")

    def fmt(v):
        return "never" if v is None else f"{v} ({v * PERIOD_S:.0f} s)"
    for k in ("q15", "trainer"):
        vals = follow[k]
        ok = sorted(v for v in vals if v is not None)
        print(f"None -> Cylinder, periods until {k} names Cylinder for good: "
              + ", ".join(fmt(v) for v in vals)
              + (f"; median {statistics.median(ok)}" if ok else ""))
        print(f"  Cylinder-L at the end of the stream ({k}): " + ", ".join(cyl_l[k]))
    return 0


if __name__ == "__main__":
    sys.exit(main())

#!/usr/bin/env python3
"""Issue 12's detection bar beside the cut that fine-tuning reaches on the
same set's clean twin (a diagnostic beside bench/residual_run_line.py; not
a test, not the bar).

  residual_twin_cut.py line CASE SEED SET_DIR TWIN_JSON
  residual_twin_cut.py table LINES_FILE

line: SET_DIR is one set of bench/residual_detection.sh (SET_DIR/residual.json
of `hadynet residual --fix` on the logs with the effect switched on);
TWIN_JSON the JSON of `hadynet residual --fix --fix-min-excess-null 0` on
the same seed's grasps recorded without the effect (the clean twin,
bench/residual_grasps.sh: same motions and rows), whose fix.control is the
model fine-tuned alone on the twin's training rows and read on its
held-out rows. --fix-min-excess-null 0 lets --fix try candidates on clean
logs, but it fine-tunes the control only when a candidate reaches the
held-out test (one gained on the selection's rows); a twin without one
gives no reading.

The plant draws the same noise with and without an effect, so a perfect
account of a sensor delay, a cross-talk or a tension leak hands
fine-tuning nearly the twin's data, and its after is about the twin's
control. The **twin's cut** is the mean over the bar's channels
(residual_run_line.cut_channels) of the twin's control / the set's
before: about the cut such an account reaches. It is not a floor:
fine-tuning is deterministic, but the held-out rows end where the run's
largest sensor delay allows (d rows short of each log's end), so a set
whose fix plans a delay is fine-tuned and read on a few rows fewer than
its twin (the line prints both held-out counts when they differ). Also
printed: the same mean of the twin's before (the unchanged model, no
fine-tuning). Drift, friction and the dead time have twins in
distribution only: drift's walk draws from the sensor noise's generator,
and friction and the dead time change the motion itself (the twin is the
same commands without them, so its error need not be within any
account's reach). Not measured: a rail and a calibration curve, which
change the readings' scale (a rail holds a clipped loadcell at one level,
easier to predict than the force it hides: on the rail 4865 the fix read
0.65 of before and the twin's control 0.90); their lines say so and the
table leaves them out.

Prints one line:

  CASE seed SEED: bar yes|no named yes|no cut yes|no R twin T (unchanged
  model T0) within yes|no (on N channels[; held-out samples S, twin S2])

(cut: the bar's, residual_run_line.py's, at most 0.7; R the same ratio
with three decimals; within: T at most 0.7.) A set with nothing applied
says so, as does one whose twin has no fix.control.

table: per case, the sets read, passed, named but short of the cut, of
those the ones whose twin's cut is above 0.7, every set whose twin's cut
is above 0.7, the median twin's cut, and over the named sets the mean
and standard deviation of R - T (how far the fix's cut lies from the
twin's: about 0 where the fix is the perfect account).
"""
import json
import os
import re
import statistics
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from residual_run_line import cut_channels, rmse_of, run_line  # noqa: E402

BAR_CUT = 0.7  # the bar's largest after/before (issue 12)
NOT_MEASURED = ("saturation", "sensor-curve")  # the module's doc says why


def line(case, seed, set_dir, twin_json):
    path = os.path.join(set_dir, "residual.json")
    bar_line = run_line(case, seed, path, "")
    m = re.match(r"\S+ seed \d+: named (yes|no) +cut (yes|no) +\(after/before (\S+)\) <control (yes|no)", bar_line)
    if not m:
        sys.exit(f"residual_twin_cut: residual_run_line.py's line is not in the form read here: {bar_line}")
    named = m.group(1) == "yes"
    bar = named and m.group(2) == "yes" and m.group(4) == "yes"
    out = f"{case} seed {seed}: bar {'yes' if bar else 'no '} named {'yes' if named else 'no '} "
    if case.split("=")[0] in NOT_MEASURED:
        return out + "not measured (the effect changes the readings' scale: the twin's error bounds nothing)"
    fix = json.load(open(path))["fix"]
    channels = cut_channels(fix)
    if not channels:
        return out + "(nothing applied)"
    twin = json.load(open(twin_json))["fix"]
    if not (twin.get("control") and twin.get("before")):
        return out + "not measured (the twin's --fix reached no held-out test, so no fine-tuning alone)"
    before, after = rmse_of(fix, "before"), rmse_of(fix, "after")
    twin_control, twin_before = rmse_of(twin, "control"), rmse_of(twin, "before")
    missing = [c for c in channels if c not in twin_control]
    if missing:
        sys.exit(f"residual_twin_cut: {twin_json} has no channel {missing[0]}")
    cut = sum(after[c] / before[c] for c in channels) / len(channels)
    twin_cut = sum(twin_control[c] / before[c] for c in channels) / len(channels)
    unchanged = sum(twin_before[c] / before[c] for c in channels) / len(channels)
    rows = (fix["before"].get("samples"), twin["before"].get("samples"))
    differ = None not in rows and rows[0] != rows[1]
    return (out + f"cut {'yes' if m.group(2) == 'yes' else 'no '} {cut:.3f} twin {twin_cut:.3f} "
            f"(unchanged model {unchanged:.3f}) within {'yes' if twin_cut <= BAR_CUT else 'no '} "
            f"(on {len(channels)} channels" + (f"; held-out samples {rows[0]}, twin {rows[1]}" if differ else "")
            + ")")


def table(path):
    rows = {}
    pattern = re.compile(r"(\S+) seed (\d+): bar (yes|no) +named (yes|no) +cut (yes|no) +(\S+) twin (\S+) "
                         r".*within (yes|no)")
    for text in open(path):
        m = pattern.match(text)
        if not m:
            continue
        r = rows.setdefault(m.group(1), {"sets": 0, "passed": 0, "short": [], "short_out": [], "out": [],
                                         "twin": [], "gap": []})
        bar, named, within = m.group(3) == "yes", m.group(4) == "yes", m.group(8) == "yes"
        cut, twin_cut = float(m.group(6)), float(m.group(7))
        short = named and m.group(5) == "no"
        r["sets"] += 1
        r["passed"] += bar
        r["twin"].append(twin_cut)
        if named:
            r["gap"].append(cut - twin_cut)
        if short:
            r["short"].append(m.group(2))
            if not within:
                r["short_out"].append(m.group(2))
        if not within:
            r["out"].append(m.group(2))
    out = ["| case | sets read | passed | named, cut short | of those, twin's cut above 0.7 "
           "| every set with twin's cut above 0.7 | median twin's cut | named: cut - twin's, mean (sd) |",
           "|---|---|---|---|---|---|---|---|"]
    for case in sorted(rows):
        r = rows[case]
        gap = (f"{statistics.mean(r['gap']):+.3f} ({statistics.stdev(r['gap']):.3f})" if len(r["gap"]) > 1
               else "-")
        out.append(f"| {case} | {r['sets']} | {r['passed']} | {len(r['short'])} | "
                   f"{len(r['short_out'])} ({', '.join(r['short_out']) or '-'}) | {len(r['out'])} | "
                   f"{statistics.median(r['twin']):.3f} | {gap} |")
    return "\n".join(out)


if __name__ == "__main__":
    args = sys.argv[1:]
    if args in (["-h"], ["--help"]):
        print(__doc__)
        sys.exit(0)
    if len(args) == 5 and args[0] == "line":
        print(line(args[1], int(args[2]), args[3], args[4]))
    elif len(args) == 2 and args[0] == "table":
        print(table(args[1]))
    else:
        print(__doc__, file=sys.stderr)
        sys.exit(2)

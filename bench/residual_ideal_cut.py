#!/usr/bin/env python3
"""Issue 12's detection bar beside the cut a perfect account of the effect
could reach on the same set (a diagnostic beside bench/residual_run_line.py;
not a test, not the bar).

  residual_ideal_cut.py line CASE SEED SET_DIR TWIN_JSON
  residual_ideal_cut.py table LINES_FILE

line: SET_DIR is one set of bench/residual_detection.sh (SET_DIR/residual.json
of `hadynet residual --fix` on the logs with the effect switched on);
TWIN_JSON the JSON of `hadynet residual --fix --fix-min-excess-null 0` on
the same seed's grasps recorded without the effect (the clean twin,
bench/residual_grasps.sh: same motions, rows and held-out rows), whose
fix.control is the model fine-tuned alone on the twin's training rows and
read on its held-out rows (--fix-min-excess-null 0 lets --fix try a
candidate, and so fine-tune the control, on clean logs).

A perfect account of a sensor delay, a cross-talk or a tension leak hands
fine-tuning the twin's data (the plant draws the same noise with and
without an effect), so its after is about the twin's control. The **ideal
cut** is the mean over the bar's channels (residual_run_line.cut_channels)
of the twin's control / the set's before; the bar asks for at most 0.7,
so a set whose ideal cut is above 0.7 cannot pass it with such an account.
Also printed: the same mean of the twin's before (the unchanged model, no
fine-tuning). Drift, friction and the dead time have twins in
distribution only: drift's walk draws from the sensor noise's generator,
and friction and the dead time change the motion itself (the twin is the
same commands without them). Not measured: a rail and a calibration curve,
which change the readings' scale (a rail holds a clipped loadcell at one
level, easier to predict than the force it hides: on the rail 4865 the
fix read 0.65 of before and the twin's control 0.90), so the twin's error
bounds nothing there; their lines say so and the table leaves them out.

Prints one line:

  CASE seed SEED: bar yes|no named yes|no cut yes|no R ideal I (unchanged
  model I0) reachable yes|no (on N channels)

(cut: the bar's, residual_run_line.py's, at most 0.7, and its R.)

A set with nothing applied says so (no channels to read), as does one
whose twin's --fix tried no candidate (no fix.control: even at
--fix-min-excess-null 0 the screen can propose nothing).

table: per case, sets, passed, named but short of the cut, of those the
ones whose ideal cut is above 0.7, every set whose ideal cut is above 0.7,
and the median ideal cut.
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
        sys.exit(f"residual_ideal_cut: residual_run_line.py's line is not in the form read here: {bar_line}")
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
        return out + "not measured (the twin's --fix tried nothing, so fine-tuned nothing alone)"
    before = rmse_of(fix, "before")
    twin_control, twin_before = rmse_of(twin, "control"), rmse_of(twin, "before")
    missing = [c for c in channels if c not in twin_control]
    if missing:
        sys.exit(f"residual_ideal_cut: {twin_json} has no channel {missing[0]}")
    ideal = sum(twin_control[c] / before[c] for c in channels) / len(channels)
    unchanged = sum(twin_before[c] / before[c] for c in channels) / len(channels)
    return (out + f"cut {'yes' if m.group(2) == 'yes' else 'no '} {m.group(3)} ideal {ideal:.2f} (unchanged model {unchanged:.2f}) "
            f"reachable {'yes' if ideal <= BAR_CUT else 'no '} (on {len(channels)} channels)")


def table(path):
    rows = {}
    pattern = re.compile(r"(\S+) seed (\d+): bar (yes|no) +named (yes|no) +cut (yes|no) +\S+ ideal (\S+) .*reachable (yes|no)")
    for text in open(path):
        m = pattern.match(text)
        if not m:
            continue
        r = rows.setdefault(m.group(1), {"sets": 0, "passed": 0, "short": [], "short_out": [], "out": [], "ideal": []})
        bar, named, reachable = m.group(3) == "yes", m.group(4) == "yes", m.group(7) == "yes"
        short = named and m.group(5) == "no"
        r["sets"] += 1
        r["passed"] += bar
        r["ideal"].append(float(m.group(6)))
        if short:
            r["short"].append(m.group(2))
            if not reachable:
                r["short_out"].append(m.group(2))
        if not reachable:
            r["out"].append(m.group(2))
    out = ["| case | sets read | passed | named, cut short | of those, ideal cut above 0.7 "
           "| every set with ideal cut above 0.7 | median ideal cut |",
           "|---|---|---|---|---|---|---|"]
    for case in sorted(rows):
        r = rows[case]
        out.append(f"| {case} | {r['sets']} | {r['passed']} | {len(r['short'])} | "
                   f"{len(r['short_out'])} ({', '.join(r['short_out']) or '-'}) | {len(r['out'])} | "
                   f"{statistics.median(r['ideal']):.2f} |")
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

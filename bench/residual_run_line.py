"""One run's line and the table of issue 12's detection benchmarks (not a
test), shared by bench/residual_detection.sh and bench/residual_oracle.sh.

  residual_run_line.py line CASE SEED FIX_JSON PROGRESS
      prints "CASE seed SEED: named yes|no cut yes|no (after/before R)
      <control yes|no | confirmed|not confirmed: EFFECT: DESCRIPTION PROGRESS":
        named     --fix confirmed the right effect with the right parameter
                  (bench/residual_named.py's rule for the plant effect);
        cut       the held-out 1-step RMSE on the changed channels (mean
                  ratio after/before) is at most 0.7 (the changed channels
                  the decision judged, with those of every wider plan
                  applied after it (fix.extensions: its own test's; since
                  stop 69, before which a drift confirmed on fc3 and then
                  applied on its whole group was cut on fc3 alone), or a
                  simpler account's, when one was applied: its own test's);
        <control  the augmented model's summed RMSE there is below
                  fine-tuning alone's.
  residual_run_line.py table RUNS_FILE CASE...
      the table of those lines per case (a run counts in a column when it
      passes that column and every one before it).
"""
import json
import os
import re
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from residual_named import names  # noqa: E402


def rmse_of(fix, part):
    """{channel: held-out 1-step RMSE} of fix[part] (before, after, control)."""
    return {c["channel"]: c["rmse"] for c in fix[part]["channels"]}


def cut_channels(fix):
    """The channels the bar's cut is read on (the module's doc, "cut"); []
    when nothing was applied."""
    channels = (fix.get("augmentation") or {}).get("channels", [])
    if not (fix.get("after") and fix.get("before") and channels):
        return []
    before, after = rmse_of(fix, "before"), rmse_of(fix, "after")
    # The decision's channels; a simpler account applied in the confirmed
    # change's place (fix.simpler) was confirmed on its own channels.
    simpler = fix.get("simpler") or {}
    judged = simpler["channels"] if simpler.get("applied") else fix.get("confirmation", {}).get("channels")
    # A wider plan applied after the confirmation (fix.extensions) changes
    # the channels its own test judged too.
    for wider in fix.get("extensions") or []:
        if wider.get("applied"):
            judged = list(judged or []) + [c for c in wider.get("channels", []) if c not in (judged or [])]
    # The changed channels among them: a calibration curve is judged on
    # every channel (Augmentation::judged_on_every_channel) and cut on
    # its curved ones; an aux channel's decision is on the targets it
    # explains, none of which is the aux channel itself.
    changed = [c for c in (judged or []) if c in channels]
    return [c for c in (changed or judged or channels) if c in before and c in after]


def run_line(case, seed, path, progress):
    effect, strength = case.split("=")
    strength = float(strength)
    fix = json.load(open(path))["fix"]
    aug = fix.get("augmentation") or {}
    named_effect = aug.get("effect", "-")
    confirmed = bool(fix.get("changed"))
    named = confirmed and names(effect, strength, fix)
    cut = below_control = False
    ratio = float("nan")
    tested = cut_channels(fix)
    if tested:
        before, after = rmse_of(fix, "before"), rmse_of(fix, "after")
        control = rmse_of(fix, "control") if fix.get("control") else {}
        ratio = sum(after[c] / before[c] for c in tested) / len(tested)
        cut = ratio <= 0.7
        below_control = bool(control) and sum(after[c] for c in tested) < sum(control[c] for c in tested)
    label = (aug.get("description", fix.get("status", "-")))[:60]
    return (f"{case} seed {seed}: named {'yes' if named else 'no '} cut {'yes' if cut else 'no '} "
            f"(after/before {ratio:.2f}) <control {'yes' if below_control else 'no '} | "
            f"{'confirmed' if confirmed else 'not confirmed'}: {named_effect}: {label}   {progress}")


def table(path, cases):
    rows = {c: [0, 0, 0, 0] for c in cases}
    for line in open(path):
        m = re.match(r"(\S+) seed \d+: named (yes|no) +cut (yes|no) .*<control (yes|no)", line)
        if not m or m.group(1) not in rows:
            continue
        r = rows[m.group(1)]
        r[0] += 1
        r[1] += m.group(2) == "yes"
        r[2] += m.group(2) == "yes" and m.group(3) == "yes"
        r[3] += m.group(2) == "yes" and m.group(3) == "yes" and m.group(4) == "yes"
    out = ["| effect=strength | runs | named and confirmed (right parameter) | + held-out RMSE cut >= 30 % "
           "| + below the fine-tune-only control |", "|---|---|---|---|---|"]
    for c in cases:
        r = rows[c]
        out.append(f"| {c} | {r[0]} | {r[1]} | {r[2]} | {r[3]} |")
    return "\n".join(out)


if __name__ == "__main__":
    if len(sys.argv) >= 2 and sys.argv[1] == "line" and len(sys.argv) == 6:
        print(run_line(*sys.argv[2:6]))
    elif len(sys.argv) >= 3 and sys.argv[1] == "table":
        print(table(sys.argv[2], sys.argv[3:]))
    else:
        print(__doc__)
        sys.exit(0 if len(sys.argv) == 2 and sys.argv[1] in ("-h", "--help") else 2)

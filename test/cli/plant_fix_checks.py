"""Checks shared by the CLI tests of `hadynet residual --fix` on plant logs
(residual_plant_delay_test.sh, residual_rail_simpler_test.sh,
residual_leak_between_groups_test.sh, residual_drift_rival_test.sh,
residual_drift_group_rival_test.sh, residual_crosstalk_source_test.sh,
residual_drift_full_screen_test.sh, residual_curve_as_rival_test.sh,
residual_other_group_rival_test.sh, residual_curve_rail_test.sh,
residual_upper_rail_test.sh, residual_rival_tie_test.sh).

named_with_cut(case, seed, json_path, check): the detection bench's rule
on one run (named with its parameter, cut by 30 %, below fine-tuning
alone).

lead_and_loadcells(fix, check): issue 12's bar on the fix's lead channel
(the first of the applied plan's channels: held-out RMSE cut by 30 % and
below fine-tuning alone) and the loadcells as a whole (the summed held-out
RMSE of every fc* channel below fine-tuning alone's: a fix must not buy
its lead with the rest of the group). `fix` is the JSON's "fix" object;
`check(ok, what)` records a failure. Prints what it compares.
"""


def lead_and_loadcells(fix, check):
    channels = (fix.get("augmentation") or {}).get("channels", [])
    if not fix.get("changed") or not channels:
        return
    rmse = lambda part: {c["channel"]: c["rmse"] for c in fix[part]["channels"]}
    before, control, after = rmse("before"), rmse("control"), rmse("after")
    w = channels[0]
    print(f"{w}: before {before[w]:.4g}, fine-tuning alone {control[w]:.4g}, fixed {after[w]:.4g}")
    check(after[w] <= 0.7 * before[w] and after[w] < control[w], f"{w}: not cut by 30 % below fine-tuning alone")
    fc = [c for c in before if c.startswith("fc")]
    total_after, total_control = sum(after[c] for c in fc), sum(control[c] for c in fc)
    print(f"summed loadcell RMSE: fixed {total_after:.4g}, fine-tuning alone {total_control:.4g}")
    check(total_after < total_control, "the loadcells as a whole not below fine-tuning alone")


def checked_fix(json_path):
    """The JSON file's "fix" object, its augmentation ({} when none) and
    (check, finish): check(ok, what) records a failure; finish() prints
    every failure and exits 1 when there is one, else 0."""
    import json
    import sys
    fix = json.load(open(json_path))["fix"]
    failures = []

    def check(ok, what):
        if not ok:
            failures.append(what)

    def finish():
        for f in failures:
            print("FAIL:", f)
        sys.exit(1 if failures else 0)

    return fix, fix.get("augmentation") or {}, check, finish


def named_with_cut(case, seed, json_path, check):
    """The detection bench's rule on one run (bench/residual_run_line.py,
    which must be importable): the plant effect `case` ("drift=0.02") named
    with its parameter, the held-out RMSE of the changed channels cut by
    30 % and below fine-tuning alone. Prints the bench's line."""
    import re
    from residual_run_line import run_line
    line = run_line(case, seed, json_path, "")
    print(line)
    check(re.search(r"named yes cut yes .*<control yes", line) is not None,
          f"{case}: not named with a cut of 30 % below fine-tuning alone")

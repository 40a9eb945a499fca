#!/usr/bin/env python3
"""Per-effect pass rates of issue 12's detection bar over several blocks of
fresh sets (not a test): how often the bar's rule passes, with a 95 %
interval, and what that rate makes of the bar itself (9 of 10 in one block).

  residual_pass_rates.py [--case EFFECT=STRENGTH]... RUNS_FILE...

RUNS_FILE: a runs.txt of bench/residual_detection.sh (its lines, written by
bench/residual_run_line.py). A run passes when it is named, cut by 30 % and
below the fine-tune-only control (the last column of residual_run_line.py's
table); a run whose `hadynet residual` failed ("residual failed") counts as
a run that did not pass. A set (case and seed) may appear once over all the
files. Blocks run with different code must not be pooled: pass only files
of one code, on seeds nothing was chosen on.

--case EFFECT=STRENGTH: only these cases (repeatable; default: every case
in the files). The bar is at the larger strengths, so a run of all sixteen
cases is read with the eight larger ones named here.

Prints a table, cases in name order: passed / runs; the Wilson score
interval at 95 % (binomial, runs taken as independent); and P(>= 9 of 10),
the chance that a block of 10 fresh sets meets the bar at the observed rate
(on the last row, that every case meets it in one block: the product,
cases taken as independent). Then the misses by cause:
  named, short    the right effect with the right parameter was applied,
                  and its cut (30 %) or the control missed;
  not confirmed   nothing was applied (the line's effect is the tested
                  choice's, or "-" when none was tested);
  wrong fix       a change was confirmed and applied that the bench's rule
                  does not name (another effect, parameter or channels the
                  rule does not accept);
  failed          `hadynet residual` failed;
and passed / named with P(>= 9 of 10) at that rate: an estimate of the
bar's chance if every run named its effect and the cut and the control
missed as often as on the named runs (n/a where no run was named). It is
an estimate, not a bound: a plan other than the one applied may cut more,
and sets that were not named may cut better or worse than named ones.
A line that names a set ("CASE seed S:") but is neither a run's line nor
a failed run's is reported on stderr and not counted. Exit status 2 for
bad arguments or files, or when the files hold no run of the cases asked
for.
"""
import math
import re
import sys

LINE = re.compile(r"(\S+) seed (\d+): named (yes|no) +cut (yes|no) .*<control (yes|no) +\| (confirmed|not confirmed):")
FAILED = re.compile(r"(\S+) seed (\d+): residual failed")  # residual_detection.sh's line for a failed run
SET = re.compile(r"(\S+) seed (\d+):")  # any line that names a set
Z95 = 1.959964  # two-sided 95 % normal quantile


def wilson(passes, runs, z=Z95):
    """The Wilson score interval (low, high) of a binomial proportion."""
    if runs == 0:
        return (0.0, 1.0)
    p = passes / runs
    centre = (p + z * z / (2 * runs)) / (1 + z * z / runs)
    half = z / (1 + z * z / runs) * math.sqrt(p * (1 - p) / runs + z * z / (4 * runs * runs))
    return (max(0.0, centre - half), min(1.0, centre + half))


def at_least(k, n, p):
    """P(X >= k) for X ~ Binomial(n, p)."""
    return sum(math.comb(n, i) * p**i * (1 - p) ** (n - i) for i in range(k, n + 1))


CAUSES = ("named, short", "not confirmed", "wrong fix", "failed")


def outcome(m):
    """A run line's outcome: "passed" or its miss's cause (CAUSES); m: LINE's match, None for a failed run."""
    if m is None:
        return "failed"
    named, cut, control, confirmed = m.group(3) == "yes", m.group(4) == "yes", m.group(5) == "yes", m.group(6)
    if named:
        return "passed" if cut and control else "named, short"
    return "not confirmed" if confirmed == "not confirmed" else "wrong fix"


def count(paths, cases=None):
    """{case: {"runs": n, "passed": n, cause: n...}} over the files; ValueError for a set seen twice."""
    counts = {}
    where = {}  # (case, seed) -> the file it was first seen in
    for path in paths:
        with open(path) as f:
            for line in f:
                m = LINE.match(line)
                failed = None if m else FAILED.match(line)
                if not m and not failed:
                    if SET.match(line):
                        print(f"residual_pass_rates: {path}: not a run's line, not counted: {line.strip()[:120]}",
                              file=sys.stderr)
                    continue
                key = ((m or failed).group(1), (m or failed).group(2))
                if cases and key[0] not in cases:
                    continue
                if key in where:
                    raise ValueError(f"{key[0]} seed {key[1]} is counted twice: in {where[key]} and in {path}")
                where[key] = path
                c = counts.setdefault(key[0], dict.fromkeys(("runs", "passed") + CAUSES, 0))
                c["runs"] += 1
                c[outcome(m)] += 1
    return counts


def rates(counts):
    out = ["| effect=strength | passed / runs | 95 % interval (Wilson) | P(>= 9 of 10) at that rate |",
           "|---|---|---|---|"]
    total = [0, 0]
    every = 1.0  # P(every case >= 9 of 10 in one block), the cases independent
    for case, c in sorted(counts.items()):
        runs, passes = c["runs"], c["passed"]
        low, high = wilson(passes, runs)
        out.append(f"| {case} | {passes} / {runs} | {low:.2f}-{high:.2f} | {at_least(9, 10, passes / runs):.2f} |")
        total[0] += runs
        total[1] += passes
        every *= at_least(9, 10, passes / runs)
    low, high = wilson(total[1], total[0])
    out.append(f"| every effect | {total[1]} / {total[0]} | {low:.2f}-{high:.2f} | {every:.2f} (all at once) |")
    return "\n".join(out)


def causes(counts):
    """The misses by cause, and the bar's chance with every run named (passed / named)."""
    out = ["| effect=strength | " + " | ".join(CAUSES) + " | passed / named | P(>= 9 of 10) at that rate |",
           "|---|" + "---|" * (len(CAUSES) + 2)]
    total = dict.fromkeys(("passed",) + CAUSES, 0)
    every = 1.0  # None once a case has no named run: the product is undefined
    for case, c in sorted(counts.items()):
        named = c["passed"] + c["named, short"]
        chance = at_least(9, 10, c["passed"] / named) if named else None
        every = every * chance if every is not None and chance is not None else None
        for k in total:
            total[k] += c[k]
        out.append(f"| {case} | " + " | ".join(str(c[k]) for k in CAUSES) +
                   f" | {c['passed']} / {named} | {'n/a' if chance is None else f'{chance:.2f}'} |")
    named = total["passed"] + total["named, short"]
    out.append("| every effect | " + " | ".join(str(total[k]) for k in CAUSES) +
               f" | {total['passed']} / {named} | {'n/a' if every is None else f'{every:.2f}'} (all at once) |")
    return "\n".join(out)


def main(argv):
    if len(argv) == 1 and argv[0] in ("-h", "--help"):
        print(__doc__)
        return 0
    cases, paths = [], []
    i = 0
    while i < len(argv):
        if argv[i] == "--case" and i + 1 < len(argv):
            cases.append(argv[i + 1])
            i += 2
        elif argv[i].startswith("-"):
            print(__doc__)
            return 2
        else:
            paths.append(argv[i])
            i += 1
    if not paths:
        print(__doc__)
        return 2
    try:
        counts = count(paths, cases)
    except (OSError, ValueError) as e:
        print(f"residual_pass_rates: {e}", file=sys.stderr)
        return 2
    if not counts:
        print(f"residual_pass_rates: no run{' of ' + ', '.join(cases) if cases else ''} in {', '.join(paths)}",
              file=sys.stderr)
        return 2
    print(rates(counts))
    print()
    print(causes(counts))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))

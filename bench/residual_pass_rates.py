#!/usr/bin/env python3
"""Per-effect pass rates of issue 12's detection bar over several blocks of
fresh sets (not a test): how often the bar's rule passes, with a 95 %
interval, and what that rate makes of the bar itself (9 of 10 in one block).

  residual_pass_rates.py RUNS_FILE...

RUNS_FILE: a runs.txt of bench/residual_detection.sh (its lines, written by
bench/residual_run_line.py). A run passes when it is named, cut by 30 % and
below the fine-tune-only control (the table's last column). Blocks run with
different code must not be pooled: pass only files of one code, on seeds
nothing was chosen on.

Prints, per effect=strength: passes / runs; the Wilson score interval at
95 % (binomial, runs taken as independent); and P(>= 9 of 10), the chance
that a block of 10 fresh sets meets the bar at the observed rate (on the
last row, that every effect meets it in one block: the product).
"""
import math
import re
import sys

LINE = re.compile(r"(\S+) seed (\d+): named (yes|no) +cut (yes|no) .*<control (yes|no)")
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


def rates(paths):
    counts = {}  # case -> [runs, passes]; a (case, seed) counted once
    seen = set()
    for path in paths:
        for line in open(path):
            m = LINE.match(line)
            if not m:
                continue
            key = (m.group(1), m.group(2))
            if key in seen:
                sys.exit(f"{path}: {key[0]} seed {key[1]} is in more than one file")
            seen.add(key)
            c = counts.setdefault(m.group(1), [0, 0])
            c[0] += 1
            c[1] += m.group(3) == "yes" and m.group(4) == "yes" and m.group(5) == "yes"
    out = ["| effect=strength | passed / runs | 95 % interval (Wilson) | P(>= 9 of 10) at that rate |",
           "|---|---|---|---|"]
    total = [0, 0]
    every = 1.0  # P(every effect >= 9 of 10 in one block), the effects' blocks independent
    for case, (runs, passes) in counts.items():
        low, high = wilson(passes, runs)
        out.append(f"| {case} | {passes} / {runs} | {low:.2f}-{high:.2f} | {at_least(9, 10, passes / runs):.2f} |")
        total[0] += runs
        total[1] += passes
        every *= at_least(9, 10, passes / runs)
    if total[0]:
        low, high = wilson(total[1], total[0])
        out.append(f"| every effect | {total[1]} / {total[0]} | {low:.2f}-{high:.2f} | {every:.2f} (all at once) |")
    return "\n".join(out)


if __name__ == "__main__":
    if len(sys.argv) < 2 or sys.argv[1] in ("-h", "--help"):
        print(__doc__)
        sys.exit(0 if len(sys.argv) == 2 else 2)
    print(rates(sys.argv[1:]))

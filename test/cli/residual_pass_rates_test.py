#!/usr/bin/env python3
"""bench/residual_pass_rates.py on runs files written here: the pass rule
(named, cut and below the control, all three), the Wilson interval, the
chance of 9 of 10, and a set counted twice refused. The expected numbers
are worked by hand (Wilson 1927; binomial sums): exact to the printed two
decimals, so any change to the rule or the formulas fails."""
import os
import subprocess
import sys
import tempfile

BENCH = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "bench")
sys.path.insert(0, BENCH)
from residual_pass_rates import at_least, rates, wilson  # noqa: E402


def line(case, seed, named, cut, control):
    return (f"{case} seed {seed}: named {named:3s} cut {cut:3s} (after/before 0.50) <control {control:3s} | "
            f"confirmed: x: y   [1/10, ETA 1s]\n")


def main():
    # 8 of 10 pass; the two misses fail one column each (cut, then control).
    lines = [line("drift=0.02", s, "yes", "yes", "yes") for s in range(8)]
    lines.append(line("drift=0.02", 8, "yes", "no", "yes"))
    lines.append(line("drift=0.02", 9, "yes", "yes", "no"))
    lines += [line("friction=4", s, "yes", "yes", "yes") for s in range(10)]
    with tempfile.TemporaryDirectory() as tmp:
        a, b = os.path.join(tmp, "a.txt"), os.path.join(tmp, "b.txt")
        with open(a, "w") as f:
            f.writelines(lines[:10])
        with open(b, "w") as f:
            f.writelines(lines[10:])
        table = rates([a, b])
        # Wilson, 8 of 10 at z 1.96: 0.4902-0.9433; P(>= 9 of 10 | 0.8) = 0.3758.
        assert "| drift=0.02 | 8 / 10 | 0.49-0.94 | 0.38 |" in table, table
        # 10 of 10: 0.7225-1.00; 18 of 20: 0.6990-0.9721; all at once 0.3758 * 1.
        assert "| friction=4 | 10 / 10 | 0.72-1.00 | 1.00 |" in table, table
        assert "| every effect | 18 / 20 | 0.70-0.97 | 0.38 (all at once) |" in table, table
        # A set in two files is refused with its name.
        run = subprocess.run([sys.executable, os.path.join(BENCH, "residual_pass_rates.py"), a, a],
                             capture_output=True, text=True)
        assert run.returncode != 0 and "drift=0.02 seed 0 is in more than one file" in run.stderr, run
    assert abs(at_least(9, 10, 0.9) - 0.7361) < 1e-4
    low, high = wilson(0, 20)  # the rule of three's neighbour: 0-0.1611
    assert low == 0.0 and abs(high - 0.1611) < 1e-4
    print("ok")


if __name__ == "__main__":
    main()

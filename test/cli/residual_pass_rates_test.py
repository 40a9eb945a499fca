#!/usr/bin/env python3
"""bench/residual_pass_rates.py on runs files written here: the pass rule
(named, cut and below the control, all three; a failed run is a run that
did not pass), the Wilson interval, the chance of 9 of 10 and its product
over the cases, the --case filter, and a set counted twice refused. The
expected numbers are worked by hand (Wilson 1927; binomial sums) and
printed to two decimals, none of them within 0.001 of a rounding edge, so
the strings are exact; the direct checks allow 1e-4 (the hand values'
last digit)."""
import os
import subprocess
import sys
import tempfile

BENCH = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "bench")
SCRIPT = os.path.join(BENCH, "residual_pass_rates.py")
sys.path.insert(0, BENCH)
from residual_pass_rates import at_least, count, rates, wilson  # noqa: E402


def line(case, seed, named, cut, control):
    # residual_run_line.py's spacing: "named no  cut" (two spaces after "no").
    return (f"{case} seed {seed}: named {named:3s} cut {cut:3s} (after/before 0.50) <control {control:3s} | "
            f"confirmed: x: y   [1/10, ETA 1s]\n")


def run(*args):
    return subprocess.run([sys.executable, SCRIPT, *args], capture_output=True, text=True)


def main():
    # drift: 7 of 10 pass; the three misses fail one column each (named, cut, control).
    drift = [line("drift=0.02", s, "yes", "yes", "yes") for s in range(7)]
    drift += [line("drift=0.02", 7, "no", "yes", "yes"), line("drift=0.02", 8, "yes", "no", "yes"),
              line("drift=0.02", 9, "yes", "yes", "no")]
    # friction: 8 of 10, one miss a failed residual; and a smaller strength
    # the --case filter leaves out.
    friction = [line("friction=4", s, "yes", "yes", "yes") for s in range(8)]
    friction += ["friction=4 seed 8: residual failed\n", line("friction=4", 9, "yes", "no", "yes"),
                 line("friction=2", 0, "no", "no", "no")]
    with tempfile.TemporaryDirectory() as tmp:
        a, b = os.path.join(tmp, "a.txt"), os.path.join(tmp, "b.txt")
        with open(a, "w") as f:
            f.writelines(drift)
        with open(b, "w") as f:
            f.writelines(friction)
        table = rates(count([a, b], ["drift=0.02", "friction=4"]))
        # Wilson, 7 of 10 at z 1.96: 0.3968-0.8922; P(>= 9 of 10 | 0.7) = 0.1493.
        assert "| drift=0.02 | 7 / 10 | 0.40-0.89 | 0.15 |" in table, table
        # 8 of 10: 0.4902-0.9433; P(>= 9 of 10 | 0.8) = 0.3758.
        assert "| friction=4 | 8 / 10 | 0.49-0.94 | 0.38 |" in table, table
        # 15 of 20: 0.5313-0.8881; the product 0.1493 * 0.3758 = 0.0561.
        assert "| every effect | 15 / 20 | 0.53-0.89 | 0.06 (all at once) |" in table, table
        assert "friction=2" not in table, table
        assert "friction=2" in rates(count([b])), "without --case every case is counted"
        # The command line: --case, a set counted twice, a missing file, no runs.
        out = run("--case", "drift=0.02", a, b)
        assert out.returncode == 0 and "| drift=0.02 | 7 / 10 |" in out.stdout and "friction" not in out.stdout, out
        with open(os.path.join(tmp, "c.txt"), "w") as f:
            f.write(drift[0])
        out = run(a, os.path.join(tmp, "c.txt"))
        assert out.returncode == 2 and "drift=0.02 seed 0 is counted twice" in out.stderr, out
        out = run(os.path.join(tmp, "missing.txt"))
        assert out.returncode == 2 and "missing.txt" in out.stderr, out
        out = run("--case", "crosstalk=0.35", a)
        assert out.returncode == 2 and "no run of crosstalk=0.35" in out.stderr, out
        assert run("--frobnicate", a).returncode == 2
        assert run("--help").returncode == 0
    assert abs(at_least(9, 10, 0.9) - 0.7361) < 1e-4
    low, high = wilson(0, 20)  # 0 of 20: 0-0.1611
    assert low < 1e-12 and abs(high - 0.1611) < 1e-4
    print("ok")


if __name__ == "__main__":
    main()

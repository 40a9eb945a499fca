#!/usr/bin/env python3
"""bench/residual_friction_twin.py on friction sets and twins written here.

Each muscle's difference (set less twin) is built from its command u_m and
s_m = sign(u_m), 0 before the log's first row:
  0: 3 s0(t-1) exactly (u0 changes sign every 3 rows and is 0, so its sign
     too, every 7th row): every feature set explains its level and steps
     in full (r^2 1 within 1e-6, the ridge's size); row t's own sign (rows
     <= t, not t - 1) would not.
  1: +-0.05 alternating: sd 0.05 <= --min-sd 0.1, not read; 0.045 reads it.
  2: 2 s2(t-1) + 1.5 times a sign alternating every row: the "sign" row
     (one feature and an intercept) is the squared correlation, computed
     here independently, of level and steps, averaged over the two logs,
     which differ (printed to 3 decimals, so within 0.0006).
  3: 2 s3(t-1) - 1.5 s3(t-2) + 0.7: "sign, 1 earlier" explains it in full
     (with the intercept), "sign" not (level r^2 below 0.99);
  4: s4(t-4) + 0.5 u4(t-3): the last two rows in full, the first two not;
  5: u5(t-6): the last row in full, the others not.
Also: --muscles, every muscle by default, a set without a twin listed and
skipped, a twin with another row count refused, a malformed line named by
file and line, bad arguments refused.
The 13 mutants of the script tried (the features' row, the sd floor and
its option, r^2 and its intercept, the step's differences, the skipped
list, sign(0), the lag, each richer row's features, the mean over pairs)
are all killed."""
import math
import os
import subprocess
import sys
import tempfile

SCRIPT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "bench", "residual_friction_twin.py")
failures = []


def check(ok, what):
    if not ok:
        failures.append(what)
        print("FAIL:", what)


def sign(v):
    return 1.0 if v > 0 else (-1.0 if v < 0 else 0.0)


MUSCLES = 6


def write_log(path, rows):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "w") as f:
        f.write("# format: hadynet-log\n# dt_s: 0.2\n")
        f.write(",".join(["t"] + ["f%d" % m for m in range(MUSCLES)] + ["u%d" % m for m in range(MUSCLES)]) + "\n")
        for r in rows:
            f.write(",".join(repr(v) for v in r) + "\n")


def noise(seed, n):
    """A deterministic sequence in [-1, 1], never 0, with sign changes."""
    x, out = seed, []
    for _ in range(n):
        x = (1103515245 * x + 12345) % 2**31
        v = x / 2**30 - 1
        out.append(v if abs(v) > 0.05 else 0.3)
    return out


def at(x, t):
    return x[t] if t >= 0 else 0.0


def write_pair(root, twins, seed, name, n, phase, twin_rows_less=0):
    u = [
        [0.0 if t % 7 == 6 else (1.0 if ((t + phase) // 3) % 2 == 0 else -1.0) * (0.5 + 0.1 * (t % 4)) for t in range(n)],
        [0.3 * math.sin(0.7 * t) for t in range(n)],
        [1.0 if ((t + phase) % 5) < 2 else -1.0 for t in range(n)],
        noise(11 + phase, n),
        noise(23 + phase, n),
        noise(37 + phase, n),
    ]
    s = [[sign(v) for v in um] for um in u]
    alt = [1.0 if t % 2 else -1.0 for t in range(n)]
    d = [
        [3 * at(s[0], t - 1) for t in range(n)],
        [0.05 * alt[t] for t in range(n)],
        [2 * at(s[2], t - 1) + 1.5 * alt[t] for t in range(n)],
        [2 * at(s[3], t - 1) - 1.5 * at(s[3], t - 2) + 0.7 for t in range(n)],
        [at(s[4], t - 4) + 0.5 * at(u[4], t - 3) for t in range(n)],
        [at(u[5], t - 6) for t in range(n)],
    ]
    clean = [[0.2 * t] + [10 + m + math.sin(0.3 * t + m) for m in range(MUSCLES)] + [um[t] for um in u]
             for t in range(n)]
    fric = [[r[0]] + [r[1 + m] + d[m][t] for m in range(MUSCLES)] + r[1 + MUSCLES:] for t, r in enumerate(clean)]
    write_log(os.path.join(root, "friction=4", "seed%d" % seed, "logs", "train", name), fric)
    if twins is not None:
        write_log(os.path.join(twins, "clean", "seed%d" % seed, "train", name), clean[: n - twin_rows_less])


def read(path):
    with open(path) as f:
        lines = [line.strip() for line in f if not line.startswith("#")]
    cols = lines[0].split(",")
    return cols, [[float(v) for v in line.split(",")] for line in lines[1:]]


def muscle2(set_log, twin_log):
    """Muscle 2's difference d2 and its sign feature sign(u2(t-1)) (0 at t = 0)."""
    cols, rows = read(set_log)
    _, trows = read(twin_log)
    i, k = cols.index("f2"), cols.index("u2")
    d = [a[i] - b[i] for a, b in zip(rows, trows)]
    z = [0.0] + [sign(r[k]) for r in rows[:-1]]
    return d, z


def diff(x):
    return [x[t] - x[t - 1] for t in range(1, len(x))]


def corr2(x, y):
    mx, my = sum(x) / len(x), sum(y) / len(y)
    sxy = sum((a - mx) * (b - my) for a, b in zip(x, y))
    sxx = sum((a - mx) ** 2 for a in x)
    syy = sum((b - my) ** 2 for b in y)
    return sxy * sxy / (sxx * syy)


def run(*args):
    p = subprocess.run([sys.executable, SCRIPT, *args], capture_output=True, text=True)
    return p.returncode, p.stdout, p.stderr


def row(out, name):
    for line in out.splitlines():
        if line.startswith("| " + name + " |"):
            cells = [c.strip() for c in line.strip("|").split("|")]
            return float(cells[1]), float(cells[2])
    return None


with tempfile.TemporaryDirectory() as tmp:
    runs, twins = os.path.join(tmp, "runs"), os.path.join(tmp, "twins")
    write_pair(runs, twins, 7001, "a.csv", 60, 0)
    write_pair(runs, twins, 7001, "b.csv", 60, 1)
    write_pair(os.path.join(runs, "B"), None, 7002, "a.csv", 60, 0)  # a half without a twin

    code, out, err = run("--runs", runs, "--twins", twins, "--muscles", "0,1")
    check(code == 0, f"exit 0 ({err})")
    check("friction sets read: friction=4/7001; no twin: friction=4/7002" in out, "the set without a twin is listed and skipped")
    check("(log, muscle) pairs: 2" in out, "muscle 1's constant difference is not read: 2 pairs")
    for name in ("sign", "sign, 1 earlier", "sign, 3 earlier; command, 2 earlier", "sign and command, 5 earlier each"):
        r = row(out, name)
        check(r is not None and abs(r[0] - 1) < 1e-6 and abs(r[1] - 1) < 1e-6,
              f"{name}: d0 = 3 sign(u0(t-1)) explained in full, level and step ({r})")

    code, out, err = run("--runs", runs, "--twins", twins, "--muscles", "0,1", "--min-sd", "0.045")
    check(code == 0 and "(log, muscle) pairs: 4" in out, f"--min-sd 0.045 reads muscle 1 (sd 0.05) too ({out})")

    level, step = [], []
    for name in ("a.csv", "b.csv"):
        d, z = muscle2(os.path.join(runs, "friction=4", "seed7001", "logs", "train", name),
                       os.path.join(twins, "clean", "seed7001", "train", name))
        level.append(corr2(z, d))
        step.append(corr2(diff(z), diff(d)))
    want = (sum(level) / 2, sum(step) / 2)
    code, out, err = run("--runs", runs, "--twins", twins, "--muscles", "2")
    r = row(out, "sign")
    check(code == 0 and r is not None and abs(r[0] - want[0]) < 0.0006 and abs(r[1] - want[1]) < 0.0006
          and abs(want[0] - want[1]) > 0.01,
          f"muscle 2: the sign's r^2 is the squared correlation, level and step ({r} against {want})")

    check(abs(level[0] - level[1]) > 0.002, f"muscle 2's two logs differ ({level}): the mean is read, not one")

    # Each feature set explains in full the muscle whose difference it holds
    # and no smaller set does (level r^2 below 0.99): muscle 3 needs the sign
    # one step earlier (and the intercept: +0.7), muscle 4 the sign 4 rows
    # back and the command 3 rows back, muscle 5 the command 6 rows back.
    names = ["sign", "sign, 1 earlier", "sign, 3 earlier; command, 2 earlier", "sign and command, 5 earlier each"]
    for m, first_full in ((3, 1), (4, 2), (5, 3)):
        code, out, err = run("--runs", runs, "--twins", twins, "--muscles", str(m))
        for i, name in enumerate(names):
            r = row(out, name)
            if i >= first_full:
                check(r is not None and abs(r[0] - 1) < 1e-6 and abs(r[1] - 1) < 1e-6,
                      f"muscle {m}: '{name}' explains it in full ({r})")
            else:
                check(r is not None and r[0] < 0.99, f"muscle {m}: '{name}' does not explain it in full ({r})")

    code, out, err = run("--runs", runs, "--twins", twins)
    check(code == 0 and "(log, muscle) pairs: 10" in out,
          f"every muscle by default: all but muscle 1 read on both logs ({out})")

    bad = os.path.join(tmp, "bad")
    write_pair(os.path.join(bad, "runs"), os.path.join(bad, "twins"), 7003, "a.csv", 40, 0, twin_rows_less=1)
    code, out, err = run("--runs", os.path.join(bad, "runs"), "--twins", os.path.join(bad, "twins"))
    check(code != 0 and "40 rows, its twin" in err, f"a twin with another row count is refused ({err})")

    broken = os.path.join(tmp, "broken")
    write_pair(os.path.join(broken, "runs"), os.path.join(broken, "twins"), 7004, "a.csv", 20, 0)
    path = os.path.join(broken, "runs", "friction=4", "seed7004", "logs", "train", "a.csv")
    with open(path, "a") as f:
        f.write("9.9,1\n")  # file line 2 + 1 + 20 + 1 = 24: two metadata lines, the header, 20 rows
    code, out, err = run("--runs", os.path.join(broken, "runs"), "--twins", os.path.join(broken, "twins"))
    check(code != 0 and path + ": line 24 has 2 fields, the header 13" in err,
          f"a malformed line is named by file and line ({err})")

    code, out, err = run("--runs", runs)
    check(code != 0 and "--twins DIR are required" in err, "--twins missing is refused")
    code, out, err = run("--twins", twins, "--bogus", "1")
    check(code != 0 and "unknown argument" in err, "an unknown argument is refused")
    code, out, err = run("--help")
    check(code == 0 and "Usage: residual_friction_twin.py" in out, "--help")

print("FAILED: %d check(s)" % len(failures) if failures else "ok")
sys.exit(1 if failures else 0)

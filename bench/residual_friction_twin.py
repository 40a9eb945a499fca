#!/usr/bin/env python3
"""What the plant's friction changes in a tendon's tension, read against the
clean twin (docs/residual-experiments.md, "Friction's account against its clean twin:
three tries, none kept (stop 95)"; not a test).

A friction set of bench/residual_detection.sh (--case friction=N) and its
clean twin of bench/residual_twin_cut.sh hold the same grasps, commands and
noise draws; they differ by the plant's tendon friction alone. So, row by
row, d_m = f_m(set) - f_m(twin) is what the friction changes in tendon m's
tension (N): its force on the tendon, and the tension of the motion it
changed (the hand moves otherwise under the same commands). For every log
and muscle m (a tension column f<m> and a command column u<m>, the
plant's naming) whose d_m varies by more than --min-sd, a least-squares fit with an intercept explains d_m by features of the command
as the fix's derived inputs see them: row t uses rows <= t - 1 (the command
u(t-1) moves the hand from row t-1 to row t). For each feature set it prints
the mean r^2 over the (log, muscle) pairs of
  level: d_m(t) on the features of row t;
  step:  d_m(t) - d_m(t-1) on the features' changes, which a 1-step
         prediction of the tension must find.
Features: s = sign(u_m), the command u_m, "k earlier" = the same k rows
before.

Usage: residual_friction_twin.py --runs DIR... --twins DIR [--muscles LIST] [--min-sd N]
  --runs DIR...   bench/residual_detection.sh --out directories: every
                  friction=*/seed<S>/logs/train (one level below DIR too, as
                  bench2-style halves A/ and B/ hold them)
  --twins DIR     bench/residual_twin_cut.sh --out directory: DIR/clean/seed<S>/train
  --muscles LIST  comma-separated muscle numbers (default: every m with f<m> and u<m>)
  --min-sd N      the smallest standard deviation of d_m read (N; default 0.1)
Sets without a twin are listed and skipped. Pure Python (no numpy).

Data roles (stop 95): read on the friction sets 5030-5039 and their clean
twins (stop 94's block, development for stop 95's tries at friction's
account; nothing in this script was chosen on them). The model it is read
beside is trained on seeds 1 and 2001-2003; --min-sd only drops pairs whose
difference hardly varies and decides nothing about the loop.
"""
import glob
import os
import sys

FEATURE_SETS = [
    ("sign", lambda s, u: [lag(s, 0)]),
    ("sign, 1 earlier", lambda s, u: [lag(s, k) for k in range(2)]),
    ("sign, 3 earlier; command, 2 earlier", lambda s, u: [lag(s, k) for k in range(4)] + [lag(u, k) for k in range(3)]),
    ("sign and command, 5 earlier each", lambda s, u: [lag(s, k) for k in range(6)] + [lag(u, k) for k in range(6)]),
]


def lag(x, k):
    """x delayed by k rows, 0 before the log's first row (as long as x)."""
    k = min(k, len(x))
    return [0.0] * k + list(x[: len(x) - k])


def sign(v):
    return 1.0 if v > 0 else (-1.0 if v < 0 else 0.0)


def read_log(path):
    """(column names, rows of floats) of a HADYNET log; '#' lines are metadata."""
    with open(path) as f:
        lines = [(n, line.strip()) for n, line in enumerate(f, start=1) if line.strip() and not line.startswith("#")]
    if not lines:
        sys.exit(f"{path}: no header line")
    cols = lines[0][1].split(",")
    rows = []
    for n, line in lines[1:]:
        values = line.split(",")
        if len(values) != len(cols):
            sys.exit(f"{path}: line {n} has {len(values)} fields, the header {len(cols)}")
        try:
            rows.append([float(v) for v in values])
        except ValueError:
            sys.exit(f"{path}: line {n}: a field is not a number")
    return cols, rows


def column(cols, rows, name):
    i = cols.index(name)
    return [r[i] for r in rows]


def solve(a, b):
    """a x = b by Gaussian elimination with partial pivoting; a tiny ridge
    keeps a constant feature (a sign that never changes) from making the
    normal equations singular."""
    n = len(b)
    m = [row[:] + [b[i]] for i, row in enumerate(a)]
    scale = max(1.0, max(abs(m[i][i]) for i in range(n)))
    for i in range(n):
        m[i][i] += 1e-9 * scale
    for c in range(n):
        p = max(range(c, n), key=lambda r: abs(m[r][c]))
        m[c], m[p] = m[p], m[c]
        for r in range(c + 1, n):
            f = m[r][c] / m[c][c]
            for k in range(c, n + 1):
                m[r][k] -= f * m[c][k]
    x = [0.0] * n
    for i in range(n - 1, -1, -1):
        x[i] = (m[i][n] - sum(m[i][k] * x[k] for k in range(i + 1, n))) / m[i][i]
    return x


def r_squared(features, y):
    """1 - var(residual) / var(y) of the least-squares fit of y on the
    features and an intercept; None when y does not vary."""
    x = [[1.0] + [f[t] for f in features] for t in range(len(y))]
    n = len(x[0])
    a = [[sum(row[i] * row[j] for row in x) for j in range(n)] for i in range(n)]
    b = [sum(row[i] * yt for row, yt in zip(x, y)) for i in range(n)]
    coef = solve(a, b)
    resid = [yt - sum(c * v for c, v in zip(coef, row)) for row, yt in zip(x, y)]
    mean_y = sum(y) / len(y)
    var_y = sum((v - mean_y) ** 2 for v in y) / len(y)
    if var_y == 0:
        return None
    mean_r = sum(resid) / len(resid)
    var_r = sum((v - mean_r) ** 2 for v in resid) / len(resid)
    return 1 - var_r / var_y


def sd(x):
    mean = sum(x) / len(x)
    return (sum((v - mean) ** 2 for v in x) / len(x)) ** 0.5


def diff(x):
    return [x[t] - x[t - 1] for t in range(1, len(x))]


def fits(set_log, twin_log, muscles, min_sd):
    """{feature set: ([level r^2], [step r^2])} over the muscles of one log."""
    cols, rows = read_log(set_log)
    tcols, trows = read_log(twin_log)
    if len(rows) != len(trows):
        sys.exit(f"{set_log}: {len(rows)} rows, its twin {twin_log} {len(trows)}")
    if muscles is None:
        muscles = [c[1:] for c in cols if c.startswith("u") and c[1:].isdigit() and "f" + c[1:] in cols]
    out = {name: ([], []) for name, _ in FEATURE_SETS}
    for m in muscles:
        if "f" + m not in cols or "u" + m not in cols or "f" + m not in tcols:
            sys.exit(f"{set_log}: no columns f{m} and u{m} (and f{m} in its twin)")
        d = [a - b for a, b in zip(column(cols, rows, "f" + m), column(tcols, trows, "f" + m))]
        if sd(d) <= min_sd or sd(diff(d)) == 0:
            continue
        u = column(cols, rows, "u" + m)
        s = [sign(v) for v in u]
        for name, make in FEATURE_SETS:
            z = [lag(f, 1) for f in make(s, u)]  # row t: rows <= t - 1
            out[name][0].append(r_squared(z, d))
            out[name][1].append(r_squared([diff(f) for f in z], diff(d)))
    return out


def friction_sets(run_dirs):
    """(case, seed, train dir) of every friction set under the run
    directories, each once (directories given twice or nested are read once)."""
    found, seen = [], set()
    for run in run_dirs:
        pattern = [os.path.join(run, "friction=*", "seed*", "logs", "train"),
                   os.path.join(run, "*", "friction=*", "seed*", "logs", "train")]
        for p in pattern:
            for train in sorted(glob.glob(p)):
                real = os.path.realpath(train)
                if real in seen:
                    continue
                seen.add(real)
                seed_dir = os.path.dirname(os.path.dirname(train))
                case = os.path.basename(os.path.dirname(seed_dir))
                found.append((case, os.path.basename(seed_dir)[len("seed"):], train))
    return found


def main(argv):
    if not argv or argv[0] in ("-h", "--help"):
        print(__doc__.strip())
        return 0 if argv else 2
    runs, twins, muscles, min_sd = [], None, None, 0.1
    i = 0
    while i < len(argv):
        a = argv[i]
        if a == "--runs":
            i += 1
            while i < len(argv) and not argv[i].startswith("--"):
                runs.append(argv[i])
                i += 1
            continue
        if a not in ("--twins", "--muscles", "--min-sd") or i + 1 >= len(argv):
            sys.exit(f"residual_friction_twin: unknown argument or missing value: {a} (--help)")
        v = argv[i + 1]
        if a == "--twins":
            twins = v
        elif a == "--muscles":
            muscles = [m.strip() for m in v.split(",") if m.strip()]
            if not muscles or not all(m.isdigit() for m in muscles):
                sys.exit(f"residual_friction_twin: --muscles '{v}' is not a list of muscle numbers (--help)")
        else:
            try:
                min_sd = float(v)
            except ValueError:
                sys.exit(f"residual_friction_twin: --min-sd '{v}' is not a number (--help)")
        i += 2
    if not runs or twins is None:
        sys.exit("residual_friction_twin: --runs DIR... and --twins DIR are required (--help)")
    level = {name: [] for name, _ in FEATURE_SETS}
    step = {name: [] for name, _ in FEATURE_SETS}
    read, skipped = [], []
    for case, seed, train in friction_sets(runs):
        twin = os.path.join(twins, "clean", "seed" + seed, "train")
        if not os.path.isdir(twin):
            skipped.append(f"{case}/{seed}")
            continue
        read.append(f"{case}/{seed}")
        for log in sorted(glob.glob(os.path.join(train, "*.csv"))):
            other = os.path.join(twin, os.path.basename(log))
            if not os.path.isfile(other):
                sys.exit(f"{log}: its twin {other} is missing")
            for name, (lv, st) in fits(log, other, muscles, min_sd).items():
                level[name] += lv
                step[name] += st
    pairs = len(level[FEATURE_SETS[0][0]])
    if not pairs:
        sys.exit("residual_friction_twin: no friction set with a twin and a varying difference")
    print(f"friction sets read: {' '.join(read)}" + (f"; no twin: {' '.join(skipped)}" if skipped else ""))
    print(f"(log, muscle) pairs: {pairs}")
    print("| features (rows <= t - 1) | level r^2, mean | step r^2, mean |")
    print("|---|---|---|")
    for name, _ in FEATURE_SETS:
        print(f"| {name} | {sum(level[name]) / pairs:.3f} | {sum(step[name]) / pairs:.3f} |")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))

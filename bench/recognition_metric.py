#!/usr/bin/env python3
"""Recognition metrics on adapted PBs (issue 17; a benchmark, not a test).

Re-scores the adapted PBs that bench/recognition_zeroings.sh wrote (one
recognize.json per zeroing: each grasp state's adapted PB) with other ways
of naming the object from the model's trained PB table, without adapting
again:

  nearest state    the nearest trained PB, Euclidean (`hadynet recognize`,
                   the paper's rule)
  nearest mean     the nearest object mean of the trained PBs, Euclidean
  within-object    the nearest object mean in the Mahalanobis metric of
                   the trained PBs' pooled within-object covariance (how a
                   re-zeroing moves an object's PB), shrunk toward its mean
                   variance by lambda: (1 - lambda) S_w + lambda tr(S_w)/p I

Per metric: accuracy, and the right object's margin (distance to the
nearest wrong object over distance to the right one, in that metric: < 1 is
a miss), 10th percentile and median.

Three disjoint sets: the metric is fitted on the trained PB table only
(the built-in model's training zeroings, inits 0-2 of dataset seed 1);
lambda is chosen on the VALIDATION zeroings (the largest 10th percentile
margin; their accuracy is 18 of 18 for every lambda from 0.05 on) and then
measured once on the MEASURED zeroings. Roles as in
bench/recognition_zeroings.sh: validation inits 4-6, measured 100-149 (used
for nothing else); the script refuses validation and measured directories
that overlap.

Usage: bench/recognition_metric.py [--model M] [--validation DIR...] --measured DIR...
  DIR: a zeroing's directory of recognition_zeroings.sh (holds recognize.json)
  e.g. bench/recognition_metric.py --validation build/recognition-zeroings/init{4,5,6} \\
         --measured build/recognition-zeroings/init{100..149}
"""
import argparse
import json
import math
import os
import struct
import sys

LAMBDAS = [0.0, 0.05, 0.1, 0.2, 0.3, 0.5, 0.7, 0.9, 1.0]


def read_pb_table(path):
    """The model's trained PBs (rows) and each row's object."""
    with open(path, 'rb') as f:
        n = struct.unpack('<Q', f.read(8))[0]
        header = json.loads(f.read(n))
        t = header['pb']
        if t['dtype'] != 'F32':
            sys.exit(f'{path}: pb is {t["dtype"]}, expected F32')
        rows, cols = t['shape']
        begin, end = t['data_offsets']
        f.seek(8 + n + begin)
        flat = struct.unpack(f'<{rows * cols}f', f.read(end - begin))
    states = json.loads(header['__metadata__']['states'])
    return [list(flat[r * cols:(r + 1) * cols]) for r in range(rows)], [s['object'] for s in states]


def inverse(a):
    """Gauss-Jordan with partial pivoting (small symmetric positive definite matrices)."""
    n = len(a)
    m = [row[:] + [1.0 if i == j else 0.0 for j in range(n)] for i, row in enumerate(a)]
    for c in range(n):
        p = max(range(c, n), key=lambda r: abs(m[r][c]))
        if abs(m[p][c]) < 1e-300:
            sys.exit('recognition_metric: singular within-object covariance (use lambda > 0)')
        m[c], m[p] = m[p], m[c]
        pivot = m[c][c]
        m[c] = [v / pivot for v in m[c]]
        for r in range(n):
            if r != c and m[r][c] != 0.0:
                factor = m[r][c]
                m[r] = [v - factor * w for v, w in zip(m[r], m[c])]
    return [row[n:] for row in m]


class Metrics:
    def __init__(self, table, objects):
        self.table, self.row_objects = table, objects
        self.objects = sorted(set(objects))
        p = len(table[0])
        self.means = {}
        for o in self.objects:
            rows = [r for r, ro in zip(table, objects) if ro == o]
            self.means[o] = [sum(col) / len(rows) for col in zip(*rows)]
        dof = len(table) - len(self.objects)
        if dof < 1:
            sys.exit('recognition_metric: one trained PB per object, no within-object spread')
        self.sw = [[0.0] * p for _ in range(p)]
        for r, o in zip(table, objects):
            d = [a - b for a, b in zip(r, self.means[o])]
            for i in range(p):
                for j in range(p):
                    self.sw[i][j] += d[i] * d[j] / dof
        self.precisions = {}

    def precision(self, lam):
        if lam not in self.precisions:
            p = len(self.sw)
            scale = sum(self.sw[i][i] for i in range(p)) / p
            s = [[(1 - lam) * self.sw[i][j] + (lam * scale if i == j else 0.0) for j in range(p)] for i in range(p)]
            self.precisions[lam] = inverse(s)
        return self.precisions[lam]

    def distances(self, pb, metric, lam=None):
        """Distance of pb to every object in the given metric."""
        if metric == 'nearest state':
            out = {}
            for r, o in zip(self.table, self.row_objects):
                d = math.dist(pb, r)
                out[o] = min(out.get(o, math.inf), d)
            return out
        if metric == 'nearest mean':
            return {o: math.dist(pb, m) for o, m in self.means.items()}
        prec = self.precision(lam)
        out = {}
        for o, m in self.means.items():
            d = [a - b for a, b in zip(pb, m)]
            out[o] = math.sqrt(max(0.0, sum(d[i] * prec[i][j] * d[j] for i in range(len(d)) for j in range(len(d)))))
        return out


def load(dirs, objects):
    grasps = []
    for d in dirs:
        path = os.path.join(d, 'recognize.json')
        with open(path) as f:
            for r in json.load(f)['results']:
                obj = r['state'].split('/')[0]
                if obj in objects:  # Cylinder-L and other unknown objects are not scored
                    grasps.append((obj, r['pb']))
    return grasps


def percentile(values, q):
    v = sorted(values)
    k = (len(v) - 1) * q / 100
    lo, hi = math.floor(k), math.ceil(k)
    return v[lo] + (v[hi] - v[lo]) * (k - lo)


def score(metrics, grasps, metric, lam=None):
    right, margins = 0, []
    for obj, pb in grasps:
        d = metrics.distances(pb, metric, lam)
        if min(d, key=d.get) == obj:
            right += 1
        wrong = min(v for o, v in d.items() if o != obj)
        margins.append(wrong / d[obj] if d[obj] > 0 else math.inf)
    return right, percentile(margins, 10), percentile(margins, 50)


def table(metrics, grasps, title):
    print(f'{title}: {len(grasps)} grasps')
    print(f'  {"metric":28s} {"right":>12s} {"margin p10":>11s} {"median":>7s}')
    rows = {}
    for metric, lam in [('nearest state', None), ('nearest mean', None)] + [('within-object', x) for x in LAMBDAS]:
        right, p10, med = score(metrics, grasps, metric, lam)
        rows[(metric, lam)] = (right, p10, med)
        name = metric if lam is None else f'{metric} lambda {lam:.2f}'
        print(f'  {name:28s} {right:4d} ({100 * right / len(grasps):5.1f} %) {p10:11.2f} {med:7.2f}')
    return rows


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n\n')[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter, epilog=__doc__)
    ap.add_argument('--model', default='models/hand.safetensors')
    ap.add_argument('--validation', nargs='+', required=True, help='zeroing directories lambda is chosen on')
    ap.add_argument('--measured', nargs='+', required=True, help='zeroing directories the choice is measured on')
    a = ap.parse_args()
    overlap = {os.path.realpath(d) for d in a.validation} & {os.path.realpath(d) for d in a.measured}
    if overlap:
        sys.exit(f'recognition_metric: validation and measured zeroings overlap: {sorted(overlap)}')
    pbs, row_objects = read_pb_table(a.model)
    metrics = Metrics(pbs, row_objects)
    val = table(metrics, load(a.validation, metrics.objects), f'validation ({len(a.validation)} zeroings)')
    lam = max(LAMBDAS, key=lambda x: val[('within-object', x)][1])
    print(f'lambda chosen on the validation zeroings (largest 10th percentile margin): {lam}')
    measured = load(a.measured, metrics.objects)
    rows = table(metrics, measured, f'measured ({len(a.measured)} zeroings)')
    base, chosen = rows[('nearest state', None)], rows[('within-object', lam)]
    print(f'measured: nearest state {base[0]} of {len(measured)}, within-object (lambda {lam}) '
          f'{chosen[0]} of {len(measured)}')


if __name__ == '__main__':
    main()

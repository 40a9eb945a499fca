#!/usr/bin/env python3
"""Summary of `hadynet recognize --json` files, one per zeroing
(bench/recognition_zeroings.sh): accuracy per object, the confusion matrix,
the margin of each grasp (distance to the nearest wrong object over distance
to the right one: > 1 right, < 1 wrong), how well `hadynet recognize`'s
confidence word separates right from wrong (a recognition is "clear" when the
nearest other object is at least CLEAR times as far as the recognised one, in
the metric `hadynet recognize` used; trainer/recognition.h) and where the
objects the model never saw land (their two nearest known objects).

Usage: bench/recognition_summary.py [--clear-margin CLEAR] RECOGNIZE.json...
  (without --clear-margin: the confidence word each file holds, from
  `hadynet recognize`'s clear margin for its metric)
"""
import json
import statistics
import sys
from collections import Counter, defaultdict


def main(args):
    if not args or args[0] in ("-h", "--help"):
        print(__doc__.strip())
        return 0 if args else 2
    clear_margin = None
    if args[0] == "--clear-margin":
        clear_margin = float(args[1])
        args = args[2:]
    paths = args
    flagged = {True: [0, 0], False: [0, 0]}  # right? -> [ambiguous, total]
    per_object = defaultdict(lambda: [0, 0])  # object -> [right, total]
    confusion = defaultdict(Counter)  # true -> recognised -> count
    margins = defaultdict(list)  # object -> margins
    unseen = defaultdict(Counter)  # unseen object -> "A + B" (its two nearest) -> count
    zeroings_all_right = 0
    for path in paths:
        with open(path) as f:
            results = json.load(f)["results"]
        all_right = True
        for r in results:
            by_distance = r["objects_by_distance"]
            known = {o["object"] for o in by_distance}
            if r["object"] not in known:
                pair = " + ".join(sorted(o["object"] for o in by_distance[:2]))
                unseen[r["object"]][pair] += 1
                continue
            right = r["recognised"] == r["object"]
            all_right &= right
            d0 = by_distance[0]["distance"]
            margin = by_distance[1]["distance"] / d0 if len(by_distance) > 1 and d0 > 0 else float("inf")
            ambiguous = r["confidence"] == "ambiguous" if clear_margin is None else margin < clear_margin
            flagged[right][0] += ambiguous
            flagged[right][1] += 1
            per_object[r["object"]][0] += right
            per_object[r["object"]][1] += 1
            confusion[r["object"]][r["recognised"]] += 1
            d_right = next(o["distance"] for o in by_distance if o["object"] == r["object"])
            d_wrong = min(o["distance"] for o in by_distance if o["object"] != r["object"])
            margins[r["object"]].append(d_wrong / d_right if d_right > 0 else float("inf"))
        zeroings_all_right += all_right
    objects = sorted(per_object)
    right = sum(v[0] for v in per_object.values())
    total = sum(v[1] for v in per_object.values())
    print(f"{len(paths)} zeroings, {total} grasps of known objects: {right} recognised right "
          f"({100.0 * right / total:.1f} %); every grasp right in {zeroings_all_right} of {len(paths)} zeroings")
    print()
    print(f"{'object':<10} {'right':>11} {'margin: min':>12} {'p10':>6} {'median':>7}")
    for o in objects:
        m = sorted(margins[o])
        p10 = m[max(0, int(0.1 * len(m)) - 1)] if m else float("nan")
        print(f"{o:<10} {per_object[o][0]:>4} of {per_object[o][1]:<4} {m[0]:>12.2f} {p10:>6.2f} "
              f"{statistics.median(m):>7.2f}")
    all_m = sorted(x for ms in margins.values() for x in ms)
    print(f"{'all':<10} {right:>4} of {total:<4} {all_m[0]:>12.2f} "
          f"{all_m[max(0, int(0.1 * len(all_m)) - 1)]:>6.2f} {statistics.median(all_m):>7.2f}")
    print()
    source = "as hadynet recognize said" if clear_margin is None else f"clear from margin {clear_margin}"
    print(f"confidence word ({source}): "
          f"{flagged[False][0]} of {flagged[False][1]} wrong recognitions called ambiguous; "
          f"{flagged[True][0]} of {flagged[True][1]} right ones called ambiguous "
          f"({100.0 * flagged[True][0] / max(1, flagged[True][1]):.0f} %)")
    print()
    print("confusion (rows: true object, columns: recognised)")
    cols = sorted({c for row in confusion.values() for c in row} | set(objects))
    print(f"{'':<10}" + "".join(f"{c:>10}" for c in cols))
    for o in objects:
        print(f"{o:<10}" + "".join(f"{confusion[o][c]:>10}" for c in cols))
    for o, pairs in sorted(unseen.items()):
        n = sum(pairs.values())
        print()
        print(f"{o} (not in the model), its two nearest known objects over {n} grasps:")
        for pair, count in pairs.most_common():
            print(f"  {pair:<22} {count:>4} ({100.0 * count / n:.0f} %)")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))

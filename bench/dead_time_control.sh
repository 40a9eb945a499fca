#!/usr/bin/env bash
# The grasp stabiliser on a hand with a command dead time (not a test): the
# plant's servos act on each command D steps late (`--effect input-delay=D`,
# declared nowhere). The residual loop fixes the build's model for it
# (`hadynet residual --fix --candidates 3` on the four residual grasps
# recorded with that dead time: lag<D>_u<m> inputs), a second build compiles
# the firmware core with the fixed model, and `hadynet stabilize` runs the
# same strikes on the delayed plant with both builds: the build's model
# (no lag inputs: it expects a command to act at once) and the fixed one,
# whose stabiliser feeds the lag inputs from its own plan (docs/residual.md,
# "Input dead time").
#
# Data roles (seeds are the plant's; nothing here is tuned, nothing chosen):
#   the fix's logs       --fix-seed (default 461; the four grasps, inits 0-2)
#   the closed loops     --first-seed .. +N-1 (default 471-480), init 3 (the
#                        test zeroing, trained on by neither model), objects
#                        Cylinder, Ball, Hammer
#
# Usage: bench/dead_time_control.sh [--delay D] [--fix-seed S] [--first-seed S] [--seeds N] [--out DIR]
#   defaults: 2, 461, 471, 10, build/dead-time-control
# Environment: HADYNET (default build/release/cli/hadynet; the build's model).
# Prints one line per closed loop with an ETA, then the table (OUT/summary.txt):
# mean E (N^2, `hadynet stabilize`'s evaluation value) over the strikes'
# steps without control, with the build's model, with the fixed model.
set -euo pipefail
usage() { sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'; }
delay=2
fix_seed=461
first_seed=471
n=10
out=build/dead-time-control
while (($#)); do
  case "$1" in
    -h | --help) usage; exit 0 ;;
    --delay) delay=$2; shift 2 ;;
    --fix-seed) fix_seed=$2; shift 2 ;;
    --first-seed) first_seed=$2; shift 2 ;;
    --seeds) n=$2; shift 2 ;;
    --out) out=$2; shift 2 ;;
    *) echo "dead_time_control: unknown argument $1" >&2; exit 2 ;;
  esac
done
cd "$(dirname "$0")/.."
source bench/residual_grasps.sh
hadynet="${HADYNET:-build/release/cli/hadynet}"
[[ -x "$hadynet" ]] || { echo "dead_time_control: $hadynet not found" >&2; exit 2; }
mkdir -p "$out"
out=$(cd "$out" && pwd)

# 1. The fix.
fix="$out/fix$fix_seed"
if [[ ! -f "$fix/fixed.safetensors" ]]; then
  rm -rf "$fix" && mkdir -p "$fix"
  echo "recording the four grasps with input-delay=$delay (seed $fix_seed) and fixing the model ..."
  collect_residual_grasps "$hadynet" "$fix/logs" "$fix_seed" --effect "input-delay=$delay"
  "$hadynet" residual models/hand.safetensors "$fix/logs" --rated-range fc=0..50 --rated-range f=0..200 --fix \
    --candidates 3 --out "$fix/fixed.safetensors" --json "$fix/residual.json" >"$fix/out.txt" 2>&1 || true
fi
python3 - "$fix/residual.json" "$delay" <<'PY'
import json, sys
fix = json.load(open(sys.argv[1]))["fix"]
aug = fix.get("augmentation") or {}
if not fix.get("changed") or aug.get("effect") != "input-delay":
    sys.exit(f"dead_time_control: the fix did not add an input delay ({aug.get('effect', 'nothing')}); see out.txt")
print(f"fix: {aug.get('description', aug.get('effect'))}")
PY

# 2. The firmware core with the fixed model (host build, hadynet only).
build="$out/build"
echo "building hadynet with the fixed model in $build ..."
cmake --preset release -B "$build" -DHADYNET_MODEL="$fix/fixed.safetensors" -DHADYNET_FIRMWARE_IMAGE_DIR=OFF >"$out/configure.log"
cmake --build "$build" --target hadynet -j "$(nproc)" >"$out/build.log"
fixed_hadynet="$build/cli/hadynet"

# 3. The closed loops.
# mean_e FILE: the mean E over steps 10.. of stabilize's CSV, columns 3 (without) and 4 (with).
mean_e() {
  python3 - "$1" <<'PY'
import csv, sys
rows = [r for r in csv.DictReader(open(sys.argv[1])) if int(r["step"]) >= 10]
w = [float(r["E_with_N2"]) for r in rows]
wo = [float(r["E_without_N2"]) for r in rows] if "E_without_N2" in rows[0] else []
print(f"{sum(wo) / len(wo) if wo else float('nan'):.4f} {sum(w) / len(w):.4f}")
PY
}
objects=(Cylinder Ball Hammer)
runs="$out/runs.txt"
: >"$runs"
total=$((n * ${#objects[@]})) done_runs=0 start=$(date +%s)
for ((k = 0; k < n; ++k)); do
  seed=$((first_seed + k))
  for object in "${objects[@]}"; do
    d="$out/$object/seed$seed"
    mkdir -p "$d"
    args=(stabilize --object "$object" --init 3 --seed "$seed" --effect "input-delay=$delay")
    "$hadynet" "${args[@]}" --csv "$d/base.csv" >"$d/base.txt"
    "$fixed_hadynet" "${args[@]}" --only-control --csv "$d/fixed.csv" >"$d/fixed.txt"
    read -r without base < <(mean_e "$d/base.csv")
    read -r _ fixed < <(mean_e "$d/fixed.csv")
    done_runs=$((done_runs + 1))
    eta=$(( ($(date +%s) - start) * (total - done_runs) / done_runs ))
    echo "$object $seed $without $base $fixed" >>"$runs"
    echo "$object seed $seed: mean E without $without, build's model $base, fixed model $fixed [$done_runs/$total, ETA ${eta}s]"
  done
done

# 4. The table.
python3 - "$runs" "$delay" "$fix_seed" "$first_seed" "$n" <<'PY' | tee "$out/summary.txt"
import math, sys
from collections import defaultdict
path, delay, fix_seed, first, n = sys.argv[1], sys.argv[2], sys.argv[3], int(sys.argv[4]), int(sys.argv[5])
rows = [l.split() for l in open(path) if l.strip()]
by = defaultdict(list)
for o, s, wo, b, f in rows:
    by[o].append((float(wo), float(b), float(f)))
print(f"input-delay={delay} in the plant; fix from seed {fix_seed}; closed loops on seeds {first}-{first + n - 1}, init 3")
print("mean E [N^2] over steps 10.. (strikes), geometric means over seeds")
print(f"{'object':10} {'without':>10} {'build model':>12} {'fixed model':>12} {'fixed/build':>12} {'fixed better':>13}")
gm = lambda v: math.exp(sum(math.log(max(x, 1e-12)) for x in v) / len(v))
for o, v in by.items():
    wo, b, f = ([x[i] for x in v] for i in range(3))
    better = sum(1 for x in v if x[2] < x[1])
    print(f"{o:10} {gm(wo):10.3f} {gm(b):12.3f} {gm(f):12.3f} {gm(f) / gm(b):12.3f} {better:>6} of {len(v)}")
PY

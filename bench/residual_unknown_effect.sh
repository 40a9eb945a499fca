#!/usr/bin/env bash
# An effect outside the residual loop's library (issue 12; not a test): does
# `hadynet residual --fix` answer "unexplained structure" (or nothing), or
# does it confirm a wrong fix? The effect exists only in this script and is
# applied to clean plant logs of the four grasps of docs/residual.md after
# recording (--effect-kind):
#   gain-wobble  (the default) fc1's gain swings with a 30 s period, as a
#                loadcell's gain with its temperature: fc1 * (1 + 0.3
#                sin(2 pi t / 30 s)), t = row * 0.2 s; no effect of the
#                library is a gain that varies in time (drift is a bias).
#   curve        fc1 reported as 50 N * (fc1 / 50 N)^0.85 (monotone,
#                compressive: +80 % at 1 N, +27 % at 10 N). Outside the
#                library until the static calibration curve (sensor-curve)
#                was added; since, a library effect on one loadcell.
# Run with the plant's rated ranges.
# Disjoint roles: the model is trained on seed 1 (collect --preset paper;
# its stored null is held-out rows of those logs; the 4-seed model of stop
# 43 on seeds 1 and 2001-2003); the null's floor was chosen on seeds 11,
# 13-16 and 181-184; no seed below is any of those.
# Seeds (curve): 221-230 (never used elsewhere; see
# bench/residual_false_positives.sh); with the calibrated null of seed 270
# (--reference-seed 270): 301-310; with the stored null and cross-talk
# sources of the target's unit: 391-400 (measured again, unchanged, after
# input delays became fixable; nothing was chosen on them); with
# sensor-curve in the library: 561-570. Seeds (gain-wobble): 571-580 (before
# the curve's plan took the winner's group only), 621-630, 741-750 (after
# the curve's plausibility bound and the rounds' changes of stop 37),
# 811-820 (stop 38: --candidates 1 and 5, the same logs), 921-930 (stop 40:
# the sensor delay's regressor on the predicted change), 1031-1040 (stop 41:
# a delay shown on other groups too planned as a dead time), 1101-1110 (stop
# 42: a cross-talk's gain re-estimated before its removal, not kept; also
# with the stop-41 binary on the same logs), 1171-1180 (stop 43: the 4-seed
# model, --model models/hand-4seeds.safetensors, trained on seeds 1 and
# 2001-2003), 1251-1260 (stop 44: --pb auto's check per channel, the
# 4-seed model), 1332-1341 (stop 46: clips on the network's channel only
# where the frame has a rail; the 4-seed model), 1377-1386 (stop 47: the
# decision on two folds; the 4-seed model), 1422-1431 (stop 48: --fix's
# candidates down to 1 by default; the 4-seed model; also at the screen's
# floor on the same logs), 1487-1496 (stop 49: the same defaults on
# 600-row logs, RESIDUAL_ROWS=600), 1782-1791 (stop 56: the drift probe;
# the 4-seed model), 1862-1871 and 1907-1916 (stop 57: one curve for the
# plan's channels, then judged on every channel; the 4-seed model),
# 1952-1961 (stop 58, before "no gain, no decision": its development, seed
# 1955) and 1977-1986 (stop 58, the final code); 2075-2084 (stop 59,
# --decision-loss absolute); 2180-2189 (stop 60: the cross-talk group's
# pairs, the squared loss; 0 of 10 confirmed); 2270-2279 (stop 61: the
# residual's unit in the held-out tests); 2355-2364 (stop 62: a cross-talk
# between groups a candidate of its own); 3620-3629 (stop 77,
# --decision-pooling logs: 0 of 10 confirmed); 3865-3874 (stop 79, a curve
# ends at its channels' rated top: 0 of 10 confirmed; 3780-3789 with the
# rule's first version: 0 of 10 confirmed); 3960-3969 (stop 80, the curve
# fitted over windows of N_train steps: 0 of 10 confirmed); 4070-4079
# (stop 81, the curve of the whole group, not kept: 0 of 10 confirmed);
# 4180-4189 (stop 82, the curve applied to the rest of its group: 0 of 10
# confirmed); 4270-4279 (stop 82's final code, a curve's rail asked where
# it was found: 0 of 10 confirmed); 4355-4364 (stop 83's final code, the
# fine-tuning loss read through the curve and a flat top through the rated
# top unless the group tops out together: 0 of 10 confirmed); 4430-4439
# (stop 84's final code, a sensor delay's steps from its group: 0 of 10
# confirmed, 3 unexplained); 4495-4504 (stop 85's final code, the curve
# refitted during fine-tuning: 0 of 10 confirmed, 0 unexplained);
# 4560-4569 (stop 86's final code, the curve's copy only where a channel
# carries load: 0 of 10 confirmed, 0 unexplained); 4635-4644 (stop 87's
# final code, a curve at its group's summed excess share, once per group:
# 0 of 10 confirmed, 5 unexplained); 4680-4689 (stop 88's final code,
# every choice's rivals also the plans of the groups it does not hold that
# gained more: 0 of 10 confirmed, 5 unexplained); 4830-4839 (stop 90's
# final code, an upper rail a candidate below the candidates' floor: 0 of
# 10 confirmed, 3 unexplained); 5020-5029 (stop 93, stop 91's code: 0 of
# 10 confirmed, 0 unexplained).
#
# Usage: bench/residual_unknown_effect.sh [--model M] [--out DIR] [--seeds N] [--first-seed S]
#          [--reference-seed S] [--effect-kind gain-wobble|curve] [--decision-loss L] [--decision-scale S] [--decision-pooling P] [--fix-selection R] [--fix-tie-break T]
#   defaults: models/hand.safetensors, build/residual-unknown-effect, 10, 221, the null of
#   `hadynet residual`'s default (the held-out logs stored in the model; --reference-seed none: no null)
#   --decision-loss L: passed to `hadynet residual --fix` (squared, its default, or absolute: its default in stop 59)
#   --decision-scale S: passed to `hadynet residual --fix` (std or residual: each channel's error in its clean residual level)
#   --decision-pooling P: passed to `hadynet residual --fix` (rows, its default, or logs: each log in its own level)
#   --fix-selection R: passed to `hadynet residual --fix` (screen-order or every-channel)
#   --fix-tie-break T: passed to `hadynet residual --fix` (largest-gain or fewest-channels)
# Environment: HADYNET (default build/release/cli/hadynet).
# Prints one line per log set with an ETA, then the counts (OUT/summary.txt).
set -euo pipefail
usage() { sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'; }
model=models/hand.safetensors
reference_seed=
out=build/residual-unknown-effect
n=10
first_seed=221
kind=gain-wobble
fix_args=()
while (($#)); do
  case "$1" in
    -h | --help) usage; exit 0 ;;
    --model) model=$2; shift 2 ;;
    --reference-seed) reference_seed=$2; shift 2 ;;
    --out) out=$2; shift 2 ;;
    --seeds) n=$2; shift 2 ;;
    --first-seed) first_seed=$2; shift 2 ;;
    --effect-kind) kind=$2; shift 2 ;;
    --decision-loss) fix_args+=(--decision-loss "$2"); shift 2 ;;
    --decision-scale) fix_args+=(--decision-scale "$2"); shift 2 ;;
    --decision-pooling) fix_args+=(--decision-pooling "$2"); shift 2 ;;
    --fix-selection) fix_args+=(--fix-selection "$2"); shift 2 ;;
    --fix-tie-break) fix_args+=(--fix-tie-break "$2"); shift 2 ;;
    *) echo "residual_unknown_effect: unknown argument $1" >&2; exit 2 ;;
  esac
done
cd "$(dirname "$0")/.."
source bench/residual_grasps.sh
hadynet="${HADYNET:-build/release/cli/hadynet}"
[[ -x "$hadynet" ]] || { echo "residual_unknown_effect: $hadynet not found" >&2; exit 2; }
mkdir -p "$out"
record_reference "$hadynet" "$out" "$reference_seed"
summary="$out/summary.txt"
: >"$summary"
start=$(date +%s)
for ((k = 0; k < n; ++k)); do
  seed=$((first_seed + k))
  d="$out/seed$seed"
  rm -rf "$d" && mkdir -p "$d/logs"
  collect_residual_grasps "$hadynet" "$d/raw" "$seed"
  # The effect, on the recorded values (comments and header kept).
  case "$kind" in
    curve) effect=curve:fc1:0.85:50 ;;
    gain-wobble) effect=wobble:fc1:0.3:30 ;;
    *) echo "residual_unknown_effect: --effect-kind must be gain-wobble or curve" >&2; exit 2 ;;
  esac
  python3 test/cli/inject_effect.py "$effect" "$d/raw" "$d/logs"
  "$hadynet" residual "$model" "$d/logs" --rated-range fc=0..50 --rated-range f=0..200 "${reference_args[@]}" --fix \
    "${fix_args[@]}" --json "$d/residual.json" >"$d/out.txt" 2>"$d/err.txt" ||
    { echo "seed $seed: residual failed: $(tail -1 "$d/err.txt")" | tee -a "$summary"; continue; }
  eta=$(( ($(date +%s) - start) * (n - k - 1) / (k + 1) ))
  python3 - "$seed" "$d/residual.json" "[$((k + 1))/$n, ETA ${eta}s]" <<'PY' | tee -a "$summary"
import json, sys
seed, path, progress = sys.argv[1:4]
j = json.load(open(path))
fix = j.get("fix", {})
outcome = "confirmed" if fix.get("changed") else ("unexplained" if fix.get("status", "").startswith("unexplained") else "nothing")
print(f"seed {seed}: {outcome}: screen {j['verdict'][:60]} | fix {fix.get('status', '-')[:50]}   {progress}")
PY
done
{
  echo "effect outside the library ($kind of fc1), $n log sets:"
  for o in confirmed unexplained nothing; do echo "  $o: $(grep -c "^seed [0-9]*: $o:" "$summary" || true)"; done
} | tee -a "$summary"

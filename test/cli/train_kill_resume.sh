#!/usr/bin/env bash
# Interrupt safety of `hadynet train`: a run killed with SIGKILL in the middle
# of training leaves a checkpoint that `--resume` continues, and the resumed
# run ends with exactly the losses of an uninterrupted run (same seed, one
# thread). Usage: train_kill_resume.sh HADYNET WORKDIR
set -euo pipefail
hadynet="$1"
work="$2"
rm -rf "$work"
mkdir -p "$work"
"$hadynet" collect --preset smoke --quiet --out "$work/data"
args=(--epochs 80 --hidden 32 --pb-size 2 --batch 20 --seed 5 --threads 1 --quiet)

"$hadynet" train "$work/data/train" --out "$work/straight.safetensors" "${args[@]}" >/dev/null

"$hadynet" train "$work/data/train" --out "$work/m.safetensors" "${args[@]}" >/dev/null &
pid=$!
for _ in $(seq 1 3000); do  # wait (at most 30 s) for the first checkpoint, then kill at once
  [[ -f "$work/m.safetensors.ckpt" ]] && break
  sleep 0.01
done
kill -9 "$pid" 2>/dev/null || { echo "training finished before it could be killed"; exit 1; }
wait "$pid" 2>/dev/null || true
[[ ! -f "$work/m.safetensors" ]] || { echo "a killed run wrote its final model"; exit 1; }
"$hadynet" train "$work/data/train" --out "$work/m.safetensors" "${args[@]}" --resume 2>"$work/resume.err" >/dev/null
grep -q "resuming .* after epoch" "$work/resume.err" || { cat "$work/resume.err"; exit 1; }
grep "resuming" "$work/resume.err"
# Same losses epoch by epoch (the seconds column differs).
cut -d, -f1-3 "$work/straight.safetensors.loss.csv" >"$work/a.csv"
cut -d, -f1-3 "$work/m.safetensors.loss.csv" >"$work/b.csv"
cmp "$work/a.csv" "$work/b.csv" || { echo "resumed losses differ from the uninterrupted run"; exit 1; }
"$hadynet" adapt "$work/m.safetensors" "$work/data/train/None_random1_i0_w0.csv" >/dev/null
echo "killed run resumed exactly"

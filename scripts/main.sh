#!/usr/bin/env bash
# The main job, end to end on the built-in defaults (the MuJoCo hand):
# install dependencies, build, record the seed paper's dataset from the plant,
# validate it and plot it, then the seed paper's experiments with the trainer
# (scripts/paper_experiments.sh: train, adapt, recognise, online PB, detection,
# simulation; summary in out/paper/summary.md), then codegen of the trained
# model and the firmware core on it (scripts/firmware_experiments.sh: replay
# of held-out logs, the grasp stabiliser in closed loop with the plant;
# summary in out/firmware/summary.md), then the residual loop on it
# (scripts/residual_experiments.sh: each plant effect named, added and
# fine-tuned, error before and after; summary in out/residual/summary.md).
# Usage: scripts/main.sh [DATA_DIR] [RESULTS_DIR]   (defaults: data/paper, out/paper)
set -euo pipefail
cd "$(dirname "$0")/.."
out="${1:-data/paper}"
results="${2:-out/paper}"

scripts/setup.sh
scripts/build.sh release
hadynet=build/release/cli/hadynet

echo "== collect: the paper preset from the MuJoCo hand -> $out"
"$hadynet" collect --preset paper --seed 1 --out "$out"
echo "== validate"
"$hadynet" validate "$out"
echo "== plot: one grasp (Random-2) log per object -> $out/plots/"
mkdir -p "$out/plots"
for log in "$out"/train/*_random2_i0_w0.csv "$out"/novel/*_random2_*.csv; do
  "$hadynet" plot "$log" --out "$out/plots/$(basename "${log%.csv}").png"
done
echo "== the seed paper's experiments -> $results"
scripts/paper_experiments.sh "$out" "$results"
echo "== codegen and the firmware core on the trained model -> out/firmware"
scripts/firmware_experiments.sh "$results/hadynet_detect.safetensors" "$out" out/firmware
echo "== the residual loop on the trained model -> out/residual"
scripts/residual_experiments.sh "$results/hadynet_detect.safetensors" out/residual

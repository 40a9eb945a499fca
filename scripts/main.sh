#!/usr/bin/env bash
# The main job, end to end on the built-in defaults (the MuJoCo hand):
# install dependencies, build, record the seed paper's dataset from the plant,
# validate it and print its summary. Later stages (train, adapt, recognise,
# codegen, replay) join here as they land.
# Usage: scripts/main.sh [OUT_DIR]   (default: data/paper)
set -euo pipefail
cd "$(dirname "$0")/.."
out="${1:-data/paper}"

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

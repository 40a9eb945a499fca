#!/usr/bin/env bash
# The residual loop on the model the main job trained (docs/residual.md):
# for each effect the MuJoCo hand can switch on (and clean logs), record the
# four effect logs of test/residual/plant_logs.h (declared nowhere), let
# `hadynet residual --fix` name the effect, add it to the model, fine-tune,
# and report the held-out error before and after; then codegen must accept
# every fixed model. Writes each effect's logs, report, JSON and fixed model
# to OUT/<effect>/ and the verdicts and before/after tables to
# OUT/summary.md.
# Usage: scripts/residual_experiments.sh [MODEL] [OUT_DIR]
#   defaults: out/paper/hadynet_detect.safetensors out/residual
set -euo pipefail
cd "$(dirname "$0")/.."
model="${1:-out/paper/hadynet_detect.safetensors}"
out="${2:-out/residual}"
hadynet=build/release/cli/hadynet
mkdir -p "$out"
summary="$out/summary.md"
printf '# The residual loop on %s (measured by scripts/residual_experiments.sh)\n' "$model" >"$summary"

# name|plant effect ("" = clean); drift and saturation at the stronger
# settings docs/residual.md explains (300-step logs do not show the defaults).
effects=("clean|" "sensor-delay|sensor-delay" "friction|friction" "crosstalk|crosstalk" "drift|drift=0.02"
         "saturation|saturation=2")
n=${#effects[@]}
i=0
start=$(date +%s)
for entry in "${effects[@]}"; do
  i=$((i + 1))
  name="${entry%%|*}"
  effect="${entry#*|}"
  dir="$out/$name"
  rm -rf "$dir"
  mkdir -p "$dir/logs"
  elapsed=$(($(date +%s) - start))
  eta=$((i > 1 ? elapsed * (n - i + 1) / (i - 1) : 0))
  echo "== [$i/$n] $name (${elapsed}s elapsed, ETA ${eta}s)"
  for o in "Cylinder random2 1" "Ball random2 2" "Gripper random2 0" "Cylinder random1 0"; do
    set -- $o
    "$hadynet" collect --object "$1" --motion "$2" --init "$3" --rows 300 --seed 1 --out "$dir/logs" \
      ${effect:+--effect "$effect"} >/dev/null
  done
  printf '\n## %s (plant: %s)\n\n```\n' "$name" "${effect:-no effect}" >>"$summary"
  "$hadynet" residual "$model" "$dir/logs" --fix --out "$dir/fixed.safetensors" --report "$dir/report" \
    --json "$dir/residual.json" 2>/dev/null | sed -n '/^verdict:/,$p' | tee -a "$summary"
  if [ -f "$dir/fixed.safetensors" ]; then
    build/release/codegen/hadynet-codegen "$dir/fixed.safetensors" --numeric q15 --out "$dir/generated" \
      --control-commands u3,u4,u5,u6,u7 | tee -a "$summary"
  fi
  printf '```\n' >>"$summary"
done
echo "== summary: $summary"

#!/usr/bin/env bash
# The seed paper's experiments on a collected paper-preset dataset, with the
# trainer: train HADYNET (variable PB) and the constant-PB comparison, adapt
# the PB to the re-initialised test states, recognise the objects (and place
# the unseen Cylinder-L), the online PB trajectory, calibrate contact
# detection on the contact-free test logs and run it with a fresh and a stale
# PB, and one contact simulation. Writes everything to OUT and a summary of
# the measured figures to OUT/summary.md (docs/trainer.md discusses them).
# Usage: scripts/paper_experiments.sh [DATA_DIR] [OUT_DIR]   (defaults data/paper, out/paper)
#        REUSE_MODELS=1 scripts/paper_experiments.sh   keeps trained models found in OUT_DIR
#        ZEROINGS=N scripts/paper_experiments.sh       recognition over N fresh zeroings (default 10)
set -euo pipefail
cd "$(dirname "$0")/.."
data="${1:-data/paper}"
out="${2:-out/paper}"
hadynet=build/release/cli/hadynet
mkdir -p "$out"
model="$out/hadynet.safetensors"
summary="$out/summary.md"

section() { echo "== $*"; printf '\n## %s\n\n```\n' "$*" >>"$summary"; }
end_section() { printf '```\n' >>"$summary"; }
record() { "$@" | tee -a "$summary"; }

printf '# HADYNET on %s (measured by scripts/paper_experiments.sh)\n' "$data" >"$summary"

section "(1) training: variable PB vs constant PB (200 epochs, loss = MSE in standardised units)"
# REUSE_MODELS=1 keeps models already in OUT (for re-running the later steps).
for variant in "$model" "$out/constant.safetensors --constant-pb"; do
  set -- $variant
  if [[ "${REUSE_MODELS:-0}" == 1 && -f "$1" ]]; then
    echo "reusing $1" | tee -a "$summary"
  else
    record "$hadynet" train "$data/train" --out "$@"
  fi
done
awk -F, 'FNR == 1 { next } { last[FILENAME] = $0 } END {
  split(last[ARGV[1]], v, ","); split(last[ARGV[2]], c, ",");
  printf "final train loss: variable %.5f, constant %.5f (variable %.1f%% lower)\n", v[2], c[2], 100 * (1 - v[2] / c[2]);
  printf "final held-out loss: variable %.5f, constant %.5f (variable %.1f%% lower)\n", v[3], c[3], 100 * (1 - v[3] / c[3]) }' \
  "$model.loss.csv" "$out/constant.safetensors.loss.csv" | tee -a "$summary"
end_section

section "(2) PB-only update on the re-initialised test states (frozen weights, MomentumSGD, full batch, 20 epochs)"
record "$hadynet" adapt "$model" "$data/test" --json "$out/adapt_test.json"
end_section

section "(3) recognition of the re-initialised test states and (4) where Cylinder-L lands"
record "$hadynet" recognize "$model" "$data/test" "$data/novel" --plot "$out/pb_map.png" \
  --json "$out/recognize.json"
end_section

section "(3b) recognition on three more re-initialisations (inits 4, 5, 6, recorded here: 12 logs each)"
for init in 4 5 6; do
  for object in None Hammer Hammer-S Cylinder Gripper Ball; do
    for motion in random1 random2; do
      "$hadynet" collect --object "$object" --motion "$motion" --init "$init" --split "init$init" \
        --out "$out/more_inits" --quiet >/dev/null
    done
  done
  record "$hadynet" recognize "$model" "$out/more_inits/init$init" --json "$out/recognize_init$init.json"
done
end_section

# ZEROINGS (default 10; bench/recognition_zeroings.sh runs 50): fresh
# zeroings, inits 100.. of dataset seed 1, used for nothing else.
zeroings="${ZEROINGS:-10}"
section "(3c) recognition over $zeroings fresh zeroings (inits 100..; bench/recognition_zeroings.sh, docs/trainer.md)"
bench/recognition_zeroings.sh --model "$model" --out "$out/zeroings" $(seq 100 $((99 + zeroings))) >&2  # progress
record cat "$out/zeroings/summary.txt"
end_section

section "(5) online PB update streaming None, then Cylinder, then Cylinder-L (test/novel Random-2 logs)"
"$hadynet" adapt "$model" "$data/test/None_random2_i3_w0.csv" "$data/test/Cylinder_random2_i3_w0.csv" \
  "$data/novel/Cylinder-L_random2_i3_w0.csv" --online --csv "$out/online_pb.csv" --plot "$out/online_pb.png"
echo "trajectory: $out/online_pb.csv, plot: $out/online_pb.png" | tee -a "$summary"
end_section

section "contact detection: calibrated on the contact-free test log None_random1 (fresh PB); None_random2 is held out"
record "$hadynet" calibrate-detect "$model" "$data/test/None_random1_i3_w0.csv" --out "$out/hadynet_detect.safetensors"
record "$hadynet" detect "$out/hadynet_detect.safetensors" "$data/test" --plot "$out/detect_fresh.png"
end_section
section "contact detection with the stale trained None PB (None/i0/w0) instead"
record "$hadynet" detect "$out/hadynet_detect.safetensors" "$data/test" --pb None/i0/w0 \
  --plot "$out/detect_stale.png"
end_section

section "contact simulation: a test grasp predicted 50 steps ahead with its adapted PB"
record "$hadynet" simulate "$model" --log "$data/test/Ball_random2_i3_w0.csv" --from 1 --horizon 50 \
  --out "$out/simulated_ball.csv" --plot "$out/simulated_ball.png"
end_section
echo "summary: $summary"

#!/usr/bin/env bash
# Codegen and the firmware core on the model the main job just trained:
# generate its q15 and f32 headers, build host-sim with it (a second build
# tree, build/main-model), replay held-out plant logs through the firmware
# (prediction, d, contact), build the Cortex-M4 images with it
# (build/main-model-m4) and replay a log through the MCU image in QEMU (must
# equal host-sim bit for bit), and run the grasp stabiliser in closed loop
# with the MuJoCo hand under the scripted strikes (E with and without).
# Writes everything to OUT and a summary to OUT/summary.md (docs/firmware.md
# discusses the figures).
# Usage: scripts/firmware_experiments.sh [MODEL] [DATA_DIR] [OUT_DIR]
#   defaults: out/paper/hadynet_detect.safetensors data/paper out/firmware
set -euo pipefail
cd "$(dirname "$0")/.."
model="${1:-out/paper/hadynet_detect.safetensors}"
data="${2:-data/paper}"
out="${3:-out/firmware}"
mkdir -p "$out"
summary="$out/summary.md"
section() { echo "== $*"; printf '\n## %s\n\n```\n' "$*" >>"$summary"; }
end_section() { printf '```\n' >>"$summary"; }
record() { "$@" 2>&1 | tee -a "$summary"; }

printf '# The firmware core on %s (measured by scripts/firmware_experiments.sh)\n' "$model" >"$summary"

section "codegen: q15 and f32 headers of the trained model (formats from its measured ranges)"
for numeric in q15 f32; do
  record build/release/codegen/hadynet-codegen "$model" --numeric "$numeric" --out "$out/generated" \
    --control-commands u3,u4,u5,u6,u7
done
end_section

section "host-sim built with this model (build/main-model)"
cmake --preset release -B build/main-model -DHADYNET_MODEL="$PWD/$model" >/dev/null
cmake --build build/main-model --target hadynet --parallel "$(nproc)" | tail -n 1
hadynet=build/main-model/cli/hadynet
record "$hadynet" replay --info
end_section

section "replay: held-out test logs through the q15 firmware (detect mode, the calibrated None PB)"
for log in "$data"/test/*_random2_i3_w0.csv; do
  name=$(basename "${log%.csv}")
  record "$hadynet" replay "$log" --out "$out/replay_$name.csv" --plot "$out/replay_$name.png"
done
end_section

section "replay: the same grasp log, q15 against f32 (the CSVs differ only by quantisation)"
record "$hadynet" replay "$data/test/Cylinder_random2_i3_w0.csv" --numeric f32 \
  --out "$out/replay_Cylinder_random2_i3_w0_f32.csv"
end_section

section "the same log through the MCU image (Cortex-M4, DSP kernels) in QEMU, over the link"
cmake --preset cortex-m4 -B build/main-model-m4 -DHADYNET_MODEL="$PWD/$model" \
  -DHADYNET_CODEGEN_EXECUTABLE="$PWD/build/main-model/codegen/hadynet-codegen" >/dev/null
cmake --build build/main-model-m4 --parallel "$(nproc)" | grep -E '^-- size' | tee -a "$summary" || true
record "$hadynet" replay "$data/test/Cylinder_random2_i3_w0.csv" --target qemu \
  --image build/main-model-m4/images/mps2-an386/hadynet-firmware.elf --out "$out/replay_Cylinder_random2_i3_w0_qemu.csv"
# Every column but the stabiliser's losses (which only host-sim reports).
strip_losses() { sed -E 's/,[^,]*,[^,]*$//' "$1"; }
if cmp -s <(strip_losses "$out/replay_Cylinder_random2_i3_w0.csv") \
          <(strip_losses "$out/replay_Cylinder_random2_i3_w0_qemu.csv"); then
  echo "QEMU (MCU image) and host-sim q15: bit-identical" | tee -a "$summary"
else
  echo "QEMU (MCU image) and host-sim q15 DIFFER" | tee -a "$summary"
  exit 1
fi
end_section

section "grasp stabiliser in closed loop with the plant: Cylinder init 3, default strikes, q15"
record "$hadynet" stabilize --object Cylinder --init 3 --periods 100 --csv "$out/stabilize.csv" \
  --plot "$out/stabilize.png"
end_section
section "a model image of this model for the build's firmware (docs/model-update.md; development key)"
if ! record build/release/cli/hadynet model-image "$model" --key keys/development.key --sequence 2 \
       --out "$out/model.img"; then
  echo "(no image: this model needs a firmware built for it; the reason is above)" | tee -a "$summary"
fi
end_section
echo "summary: $summary"

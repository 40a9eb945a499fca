#!/usr/bin/env bash
# Benchmark (not a test): what verifying a model image costs on the
# Cortex-M4, in instructions under QEMU `-icount shift=0` (mps2-an386;
# bench.h explains the count), and the time that means at the STM32F405's
# 168 MHz if every instruction took one cycle (flash wait states and
# multi-cycle instructions make the real time longer: a lower bound).
# Baseline in the same run: one q15 control period of the same build
# (bench/qemu_icount.sh's control_full job), what the MCU does every 0.2 s.
#
# The device verifies an image (SHA-256 of the payload + one Ed25519
# verification of its header) at begin_update (signature only), at
# finish_update (the payload hashed twice: the stream and the read-back)
# and for each slot at every boot (docs/model-update.md).
#
# Usage: bench/model_update_icount.sh [IMAGE_DIR]   (default build/cortex-m4/images)
set -euo pipefail
cd "$(dirname "$0")/.."
images="${1:-build/cortex-m4/images}"
qemu=qemu-system-arm
for image in hadynet-bench-model-update hadynet-bench-q15; do
  if [[ ! -f "$images/mps2-an386/$image.elf" ]]; then
    echo "model_update_icount: $images/mps2-an386/$image.elf not found (build the cortex-m4 preset)" >&2
    exit 2
  fi
done
run() {
  timeout 600 "$qemu" -M mps2-an386 -nographic -monitor none -serial stdio \
    -semihosting-config enable=on,target=native -icount shift=0 -kernel "$1" </dev/null
}
verify_out=$(run "$images/mps2-an386/hadynet-bench-model-update.elf") || {
  echo "model_update_icount: the benchmark failed:" >&2; echo "$verify_out" >&2; exit 1; }
control_out=$(run "$images/mps2-an386/hadynet-bench-q15.elf") || {
  echo "model_update_icount: the q15 benchmark failed:" >&2; echo "$control_out" >&2; exit 1; }
grep -q '^verified ok=1' <<<"$verify_out" || { echo "model_update_icount: the signature did not verify" >&2; exit 1; }

printf 'Model image verification under QEMU -icount shift=0 (mps2-an386 image, Cortex-M4 code)\n\n'
{ echo "$verify_out"; echo "CONTROL"; echo "$control_out"; } | awk '
  /^CONTROL/ { control = 1; next }
  /^bench / { for (i = 2; i <= NF; ++i) { split($i, kv, "="); if (kv[1] == "tick_hz") hz = kv[2] } }
  /^job / {
    delete f
    for (i = 2; i <= NF; ++i) { split($i, kv, "="); f[kv[1]] = kv[2] }
    per_rep = f["ticks"] * (1e9 / hz) / f["reps"]
    if (control) { if (f["name"] == "control_full") period = per_rep; next }
    cost[f["name"]] = per_rep; bytes[f["name"]] = f["bytes"]
  }
  END {
    sha = cost["sha256_payload"]; ed = cost["ed25519_verify"]
    printf "%-34s %14s %12s %10s\n", "work", "instructions", "ms @168MHz", "periods"
    row("SHA-256 of the payload (" bytes["sha256_payload"] " bytes)", sha)
    printf "%-34s %14.1f\n", "  instructions per byte", sha / bytes["sha256_payload"]
    row("Ed25519 verification (one header)", ed)
    row("one image (hash + signature)", sha + ed)
    row("begin_update (signature)", ed)
    row("finish_update (two hashes)", 2 * sha)
    row("boot, two valid slots", 2 * (sha + ed))
    row("baseline: q15 control period", period)
  }
  function row(name, n) { printf "%-34s %14.0f %12.1f %10.2f\n", name, n, n / 168e3, n / period }'

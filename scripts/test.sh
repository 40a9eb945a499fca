#!/usr/bin/env bash
# Installs dependencies, builds and runs the whole test suite: the host
# release build, the Cortex-M4 cross build of the firmware images for both
# boards (the core and its runtime with the generated q15 and f32 models; it
# must compile without warnings, link no heap or exceptions and fit each
# board's memory), then the release suite under CTest, which also runs the
# images under QEMU (test/boards/), then the libFuzzer targets (fuzz preset:
# clang, ASan + UBSan, 10 s each from their seeds), then, under ASan + UBSan
# (debug preset: clang, CMakePresets.json says why), the code that runs on the
# MCU or reads untrusted input with its tests: the build without the trainer
# (HADYNET_TRAINER OFF), whose Eigen numerics, CLI and their tests ran in the
# release suite already.
# Ends with each step's wall time, so a slow CI run shows where it went.
set -euo pipefail
cd "$(dirname "$0")/.."

step_times=()
step() {  # step COMMAND...: runs it and records its wall time in seconds
  local start=$SECONDS
  "$@"
  step_times+=("$(printf '%6d s  %s' $((SECONDS - start)) "$*")")
}
trap 'printf "%s\n" "wall time per step:" "${step_times[@]}"' EXIT

step scripts/setup.sh
# The presets chain the builds: the cross build generates its model headers
# with build/release's codegen, the release suite runs
# build/cortex-m4/images under QEMU, and the fuzz build runs build/release's
# codegen and fuzz tools (CMakePresets.json).
step scripts/build.sh release
step scripts/build.sh cortex-m4
echo "cross build (cortex-m4): ok"
step ctest --preset release
# Fails (no skip) when clang or its libFuzzer runtime (libclang-rt-dev) is
# missing.
step scripts/build.sh fuzz
step ctest --preset fuzz
step scripts/build.sh debug
step ctest --preset debug

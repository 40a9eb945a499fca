#!/usr/bin/env bash
# Installs dependencies, builds and runs the whole test suite: the host
# release build, the Cortex-M4 cross build of the firmware images for both
# boards (the core and its runtime with the generated q15 and f32 models; it
# must compile without warnings, link no heap or exceptions and fit each
# board's memory), then the release suite under CTest, which also runs the
# images under QEMU (test/boards/), then the same host suite under
# ASan + UBSan (debug preset), without the tests labelled `slow` (model
# fine-tuning; they ran in release already).
set -euo pipefail
cd "$(dirname "$0")/.."

scripts/setup.sh
# The release suite runs the cross build's images under QEMU.
scripts/build.sh release -DHADYNET_FIRMWARE_IMAGE_DIR="$PWD/build/cortex-m4/images"
# The cross build generates its model headers with the host's codegen tool.
scripts/build.sh cortex-m4 -DHADYNET_CODEGEN_EXECUTABLE="$PWD/build/release/codegen/hadynet-codegen"
echo "cross build (cortex-m4): ok"
ctest --preset release
scripts/build.sh debug
ctest --preset debug

#!/usr/bin/env bash
# Installs dependencies, builds and runs the whole test suite: the host
# release build under CTest, the same suite under ASan + UBSan (debug preset),
# then the Cortex-M4 cross build of the firmware core and its runtime with the
# generated q15 and f32 models (it must compile without warnings and link no
# heap or exceptions).
set -euo pipefail
cd "$(dirname "$0")/.."

scripts/setup.sh
scripts/build.sh release
ctest --preset release
scripts/build.sh debug
ctest --preset debug
# The cross build generates its model headers with the host's codegen tool.
scripts/build.sh cortex-m4 -DHADYNET_CODEGEN_EXECUTABLE="$PWD/build/release/codegen/hadynet-codegen"
echo "cross build (cortex-m4): ok"

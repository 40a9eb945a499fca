#!/usr/bin/env bash
# Installs dependencies, builds and runs the whole test suite: the host
# release build under CTest, the same suite under ASan + UBSan (debug preset),
# then the Cortex-M4 cross build of the firmware core (it must compile
# without warnings and link no heap or exceptions).
set -euo pipefail
cd "$(dirname "$0")/.."

scripts/setup.sh
scripts/build.sh release
ctest --preset release
scripts/build.sh debug
ctest --preset debug
scripts/build.sh cortex-m4
echo "cross build (cortex-m4): ok"

#!/usr/bin/env bash
# Configures and builds one CMake preset (default: release).
# Usage: scripts/build.sh [release|debug|cortex-m4]
set -euo pipefail
cd "$(dirname "$0")/.."
preset="${1:-release}"
cmake --preset "$preset" >/dev/null
cmake --build --preset "$preset" --parallel "$(nproc)"

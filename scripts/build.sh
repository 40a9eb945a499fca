#!/usr/bin/env bash
# Configures and builds one CMake preset (default: release).
# Usage: scripts/build.sh [release|debug|cortex-m4|fuzz] [-DVAR=VALUE ...]
#   (the extra arguments go to the configure step)
set -euo pipefail
cd "$(dirname "$0")/.."
preset="${1:-release}"
shift || true
cmake --preset "$preset" "$@" >/dev/null
cmake --build --preset "$preset" --parallel "$(nproc)"

#!/usr/bin/env bash
# Installs every Debian 12 package the project needs to build, run and test.
# Idempotent and non-interactive: packages already present are left alone and
# `apt-get update` runs only when something is missing. Needs root (or sudo).
#
# Usage: scripts/setup.sh            # build + test dependencies
#        scripts/setup.sh --bench    # also the benchmark baselines (PyTorch)
set -euo pipefail

packages=(
  # build
  cmake ninja-build g++ make pkg-config git
  # trainer, plant, tests, plots (libmujoco-dev's CMake config needs libqhull-dev's headers)
  libeigen3-dev libsodium-dev libmujoco-dev libqhull-dev libgtest-dev libgmock-dev nlohmann-json3-dev gnuplot-nox
  # firmware cross build and emulation (python3: the QEMU test runner, test/boards/qemu_run.py)
  gcc-arm-none-eabi libnewlib-arm-none-eabi libstdc++-arm-none-eabi-newlib qemu-system-arm python3
  # host USB tools and their tests
  libusb-1.0-0-dev libhidapi-dev umockdev libumockdev-dev dfu-util
  # link fuzzer (fuzz/): clang with libFuzzer and the sanitizer runtimes
  clang libclang-rt-dev
)
if [[ "${1:-}" == "--bench" ]]; then
  # OpenBLAS: without it Debian's torch falls back to the reference BLAS (an unfair baseline)
  packages+=(python3-torch python3-numpy libopenblas0-pthread
    time)  # GNU time: peak memory in bench/residual_memory.sh
fi

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed'; then
    missing+=("$p")
  fi
done

if ((${#missing[@]} == 0)); then
  echo "setup: all ${#packages[@]} packages present"
  exit 0
fi

sudo=""
if [[ $(id -u) -ne 0 ]]; then sudo="sudo"; fi
echo "setup: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$sudo apt-get update -qq
$sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
echo "setup: done"

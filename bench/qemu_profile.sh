#!/usr/bin/env bash
# Where a benchmark job's instructions go, per function (not a test;
# docs/boards.md, "Where the control period goes").
#
# Runs the q15 benchmark image of mps2-an386 under QEMU with block tracing
# (`-d in_asm,exec,nochain`, streamed through a FIFO, nothing on disk) and
# counts the instructions of each function during one job of
# firmware/app/bench.h (default: control_full, its warm-up period and its
# timed periods); bench/qemu_profile.py does the counting. About 15 s on
# the development VM.
#
# Usage: bench/qemu_profile.sh [--job N] [--top K] [IMAGE_DIR]
#   --job N    the job after the N-th report: 1 detect, 2 control_full
#              (default), 3 control, 4 adapt
#   --top K    functions to print (default 25)
#   IMAGE_DIR  images/ of a cross build (default build/cortex-m4/images)
set -euo pipefail
cd "$(dirname "$0")/.."

job=2
top=25
images=build/cortex-m4/images
while [[ $# -gt 0 ]]; do
  case "$1" in
    --job) job="$2"; shift 2 ;;
    --top) top="$2"; shift 2 ;;
    -h|--help) sed -n '2,16p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    -*) echo "qemu_profile: unknown option $1 (see --help)" >&2; exit 2 ;;
    *) images="$1"; shift ;;
  esac
done
elf="$images/mps2-an386/hadynet-bench-q15.elf"
if [[ ! -f "$elf" ]]; then
  echo "qemu_profile: $elf not found (build the cortex-m4 preset)" >&2
  exit 2
fi

work=$(mktemp -d)
counter=
# The counter blocks opening the FIFO until QEMU opens it: if QEMU never
# does, it is killed here.
trap '[[ -n "$counter" ]] && kill "$counter" 2>/dev/null; rm -rf "$work"' EXIT
mkfifo "$work/trace"
python3 bench/qemu_profile.py "$elf" --between 'hadynet::app::Bench<hadynet::model_q15::Model>::report' "$job" \
  --top "$top" < "$work/trace" &
counter=$!
# The bench's own report on stdout is not needed here.
timeout 1200 "${QEMU:-qemu-system-arm}" -M mps2-an386 -nographic -monitor none -serial null \
  -semihosting-config enable=on,target=native -d in_asm,exec,nochain -D "$work/trace" \
  -kernel "$elf" </dev/null
status=0
wait "$counter" || status=$?
counter=
exit "$status"

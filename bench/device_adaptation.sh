#!/usr/bin/env bash
# On-device PB adaptation against the trainer's online adaptation (issue 16;
# a benchmark, not a test): the firmware's adapter (firmware/core/pb_adapter.h,
# q15 and f32, in host-sim via `hadynet replay --adapt`) and the trainer's
# (`hadynet adapt --online`, the paper's rule) on the same streams of a
# re-zeroed hand, both from the PB of None/i0/w0 (a hand that held nothing
# when it started).
#
# Per zeroing it records the six trained objects' Random-2 grasps and
# Cylinder-L's (500 rows each), then
#  * each object's log alone: the object the adapted PB names at the end
#    (device q15, device f32, trainer), and the PB distances device-trainer
#    and q15-f32 over the log;
#  * the paper's online figure, None -> Cylinder -> Cylinder-L in one stream:
#    how many periods after each switch the device's label (and the
#    trainer's) names the new object for good.
# bench/device_adaptation_summary.py prints the figures.
#
# Zeroings (disjoint roles): training inits 0-2 of seed 1; init 3 the paper
# preset's test zeroing (the tests use it); inits 4-6 of seed 1 the
# validation zeroings, the only ones the adapter's window stride was chosen
# on; measured by default: inits 400-409 of seed 1, used for nothing else.
#
# Usage: bench/device_adaptation.sh [--out DIR] [--stride N] [--budget N] [--jobs N] [INIT...]
#   defaults: build/device-adaptation, the firmware's stride and budget, 2 jobs, inits 400..409
# Environment: HADYNET (default build/release/cli/hadynet). The build's
# compiled-in model (HADYNET_MODEL, models/hand.safetensors by default) is
# the one adapted; the trainer uses the same file (MODEL, default that).
# Prints one line per zeroing with an ETA, then the summary; OUT/summary.txt.
set -euo pipefail
usage() { sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'; }
out=build/device-adaptation
stride=""
budget=""
jobs=2
inits=()
while (($#)); do
  case "$1" in
    -h | --help) usage; exit 0 ;;
    --out) out=$2; shift 2 ;;
    --stride) stride=$2; shift 2 ;;
    --budget) budget=$2; shift 2 ;;
    --jobs) jobs=$2; shift 2 ;;
    -*) echo "device_adaptation: unknown option $1" >&2; exit 2 ;;
    *) inits+=("$1"); shift ;;
  esac
done
cd "$(dirname "$0")/.."
((${#inits[@]})) || inits=($(seq 400 409))
hadynet="${HADYNET:-build/release/cli/hadynet}"
model="${MODEL:-models/hand.safetensors}"
[[ -x "$hadynet" ]] || { echo "device_adaptation: $hadynet not found (scripts/build.sh release)" >&2; exit 2; }
start_state=None/i0/w0
objects=(None Hammer Hammer-S Cylinder Gripper Ball)
device_args=(--adapt --pb "$start_state")
[[ -n "$stride" ]] && device_args+=(--adapt-stride "$stride")
[[ -n "$budget" ]] && device_args+=(--adapt-budget "$budget")
tag="stride${stride:-default}-budget${budget:-default}"
mkdir -p "$out"

# One job: "kind init name logs...". Results already present are kept.
run_job() {
  local kind=$1 init=$2 name=$3
  shift 3
  local d="$out/init$init"
  case "$kind" in
    q15 | f32)
      local csv="$d/$tag/$name.$kind.csv"
      if [[ ! -f "$csv" ]]; then
        "$hadynet" replay "${device_args[@]}" --numeric "$kind" --out "$csv.tmp" "$@" >/dev/null && mv "$csv.tmp" "$csv"
      fi ;;
    trainer)
      local csv="$d/trainer/$name.csv"
      if [[ ! -f "$csv" ]]; then
        "$hadynet" adapt "$model" "$@" --online --start "$start_state" --csv "$csv.tmp" >/dev/null 2>&1 &&
          mv "$csv.tmp" "$csv"
      fi ;;
  esac
}
export -f run_job
export out tag hadynet model start_state
export device_args_str="${device_args[*]}"

i=0 t0=$(date +%s)
for init in "${inits[@]}"; do
  i=$((i + 1))
  d="$out/init$init"
  mkdir -p "$d/logs" "$d/$tag" "$d/trainer"
  for o in "${objects[@]}" Cylinder-L; do
    f="$d/logs/${o}_random2_i${init}_w0.csv"
    [[ -f "$f" ]] || "$hadynet" collect --object "$o" --motion random2 --init "$init" --split logs --out "$d" --quiet >/dev/null
  done
  switch=("$d/logs/None_random2_i${init}_w0.csv" "$d/logs/Cylinder_random2_i${init}_w0.csv"
    "$d/logs/Cylinder-L_random2_i${init}_w0.csv")
  {
    for o in "${objects[@]}"; do
      for kind in q15 f32 trainer; do echo "$kind $init $o $d/logs/${o}_random2_i${init}_w0.csv"; done
    done
    for kind in q15 f32 trainer; do echo "$kind $init switch ${switch[*]}"; done
  } | xargs -P "$jobs" -L 1 bash -c 'device_args=($device_args_str); run_job "$@"' _
  elapsed=$(($(date +%s) - t0))
  printf 'zeroing %d/%d (init %d) done, elapsed %ds, ETA %ds\n' "$i" "${#inits[@]}" "$init" "$elapsed" \
    $((elapsed * (${#inits[@]} - i) / i))
done
dirs=()
for init in "${inits[@]}"; do dirs+=("$out/init$init"); done
python3 bench/device_adaptation_summary.py --tag "$tag" "${dirs[@]}" | tee "$out/summary-$tag.txt"

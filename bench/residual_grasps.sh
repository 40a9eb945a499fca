# Sourced by the residual-loop benchmarks: the four grasps docs/residual.md
# analyses (the states of test/residual/plant_logs.h's kEffectLogs), as
# "object motion init", and how one log set of them is recorded.
residual_grasps=("Cylinder random2 1" "Ball random2 2" "Gripper random2 0" "Cylinder random1 0")

# collect_residual_grasps HADYNET OUT SEED [collect options...]: the four
# grasps, 300 rows each (environment RESIDUAL_ROWS: another length, e.g. to
# measure what longer logs give), recorded with SEED into OUT (collect's
# layout: OUT/train/*.csv and a manifest).
collect_residual_grasps() {
  local hadynet=$1 out=$2 seed=$3 g
  shift 3
  for g in "${residual_grasps[@]}"; do
    set -- $g "$@"
    "$hadynet" collect --object "$1" --motion "$2" --init "$3" --rows "${RESIDUAL_ROWS:-300}" --seed "$seed" --out "$out" \
      "${@:4}" --quiet >/dev/null || return 1
    shift 3
  done
}

# collect_rezeroed_grasps HADYNET OUT SEED INIT [collect options...]: the same
# four grasps recorded under the zeroing INIT (an init id the model never
# saw) and relabelled with their trained state names (OUT/*.csv): a hand
# re-zeroed at start-up that keeps its names (docs/residual.md, "Which PB").
# The plant's raw recordings stay in OUT.raw (beside OUT: a log directory is
# read recursively).
collect_rezeroed_grasps() {
  local hadynet=$1 out=$2 seed=$3 rezero=$4 g f
  shift 4
  mkdir -p "$out"
  for g in "${residual_grasps[@]}"; do
    set -- $g "$@"
    "$hadynet" collect --object "$1" --motion "$2" --init "$rezero" --rows "${RESIDUAL_ROWS:-300}" --seed "$seed" \
      --out "${out%/}.raw" "${@:4}" --quiet >/dev/null || return 1
    f=$(ls "${out%/}".raw/*/"$1_$2_i${rezero}_w0.csv")
    sed "s|^# state: .*|# state: $1/i$3/w0|" "$f" >"$out/$1_$2_i$3.csv"
    shift 3
  done
}

# record_reference HADYNET OUT SEED: clean log sets of the four grasps with
# SEED in OUT/reference, the calibrated null of `hadynet residual --reference`
# (docs/residual.md, "A calibrated null"), and sets reference_args to the
# options that use it. With SEED empty, reference_args is empty (the null is
# the held-out logs stored in the model, if it has any); with SEED "none",
# --reference none (no null: absolute floors).
record_reference() {
  reference_args=()
  [[ -n "$3" ]] || return 0
  if [[ "$3" == none ]]; then
    reference_args=(--reference none)
    return 0
  fi
  rm -rf "$2/reference"
  collect_residual_grasps "$1" "$2/reference" "$3"
  reference_args=(--reference "$2/reference")
}

# record_clean_twin HADYNET DIR SEED: the four grasps with SEED and no
# effect in DIR, once (kept when DIR exists; recorded into DIR.part and
# moved, so an interrupted run leaves no half twin): the clean twin of a
# set recorded with the same seed and an effect (RESIDUAL_ROWS as the set).
record_clean_twin() {
  [[ -d "$2" ]] && return 0
  rm -rf "$2.part"
  collect_residual_grasps "$1" "$2.part" "$3" || return 1
  mv "$2.part" "$2"
}

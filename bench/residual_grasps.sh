# Sourced by the residual-loop benchmarks: the four grasps docs/residual.md
# analyses (the states of test/residual/plant_logs.h's kEffectLogs), as
# "object motion init", and how one log set of them is recorded.
residual_grasps=("Cylinder random2 1" "Ball random2 2" "Gripper random2 0" "Cylinder random1 0")

# collect_residual_grasps HADYNET OUT SEED [collect options...]: the four
# grasps, 300 rows each, recorded with SEED into OUT (collect's layout:
# OUT/train/*.csv and a manifest).
collect_residual_grasps() {
  local hadynet=$1 out=$2 seed=$3 g
  shift 3
  for g in "${residual_grasps[@]}"; do
    set -- $g "$@"
    "$hadynet" collect --object "$1" --motion "$2" --init "$3" --rows 300 --seed "$seed" --out "$out" \
      "${@:4}" --quiet >/dev/null
    shift 3
  done
}

# Sourced by the CLI tests of `hadynet residual --fix` on plant logs
# (residual_plant_delay_test.sh, residual_rail_simpler_test.sh,
# residual_leak_between_groups_test.sh, residual_rounds_earlier_test.sh).
#
# plant_fix_run HADYNET MODEL WORK SEED [--rounds N] -- [collect options...]:
# the four grasps of docs/residual.md (300 rows) recorded with SEED and the
# collect options (the plant effects, declared nowhere in the logs) into
# WORK/logs, then `hadynet residual MODEL WORK/logs --rated-range fc=0..50
# --rated-range f=0..200 --fix` with the options before `--`: stdout and
# stderr in WORK/out.txt, the JSON in WORK/residual.json. Prints "FAIL: ..."
# and returns 1 when a step fails.
plant_fix_run() {
  local hadynet=$1 model=$2 work=$3 seed=$4 fix_args=()
  shift 4
  while (($#)) && [[ $1 != -- ]]; do fix_args+=("$1"); shift; done
  (($#)) && shift
  local here
  here=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
  rm -rf "$work" && mkdir -p "$work/logs" || return 1
  source "$here/bench/residual_grasps.sh"
  RESIDUAL_ROWS=300 collect_residual_grasps "$hadynet" "$work/raw" "$seed" "$@" || { echo "FAIL: collect"; return 1; }
  find "$work/raw" -name "*.csv" -exec cp {} "$work/logs/" \;
  [[ $(ls "$work/logs" | wc -l) -eq 4 ]] || { echo "FAIL: not the four grasps' logs"; return 1; }
  "$hadynet" residual "$model" "$work/logs" --rated-range fc=0..50 --rated-range f=0..200 --fix "${fix_args[@]}" \
    --json "$work/residual.json" >"$work/out.txt" 2>&1 || { echo "FAIL: residual"; tail -5 "$work/out.txt"; return 1; }
}

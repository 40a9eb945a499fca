#!/usr/bin/env bash
# Memory of `hadynet residual` on long logs (issue 12; not a test): the peak
# resident memory and the wall time of the analysis of one log of each
# length, at horizon 50 (the multi-step fit runs the network over every
# window of 50 steps), with the state's trained PB (--pb state: PB
# adaptation is not what is measured). The shortest log is the baseline of
# the same run: bounded memory means the peak does not grow with the length.
# Logs: Cylinder random2 init 1, seed 12 (development data; no figure here
# depends on what the data holds).
#
# Usage: bench/residual_memory.sh [--model M] [--out DIR] [ROWS...]
#   defaults: models/hand.safetensors, build/residual-memory, 2500 10000 40000
#   (recording 40 000 rows takes about 5 min on one core)
# Environment: HADYNET (default build/release/cli/hadynet). Needs GNU time
# (/usr/bin/time, Debian package `time`: scripts/setup.sh --bench).
# Prints a table (OUT/summary.txt).
set -euo pipefail
usage() { sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'; }
model=models/hand.safetensors
out=build/residual-memory
lengths=()
while (($#)); do
  case "$1" in
    -h | --help) usage; exit 0 ;;
    --model) model=$2; shift 2 ;;
    --out) out=$2; shift 2 ;;
    -*) echo "residual_memory: unknown option $1" >&2; exit 2 ;;
    *) lengths+=("$1"); shift ;;
  esac
done
cd "$(dirname "$0")/.."
((${#lengths[@]})) || lengths=(2500 10000 40000)
hadynet="${HADYNET:-build/release/cli/hadynet}"
[[ -x "$hadynet" ]] || { echo "residual_memory: $hadynet not found" >&2; exit 2; }
[[ -x /usr/bin/time ]] || { echo "residual_memory: /usr/bin/time not found (apt-get install time)" >&2; exit 2; }
mkdir -p "$out"
summary="$out/summary.txt"
{
  echo "| rows | peak resident memory (MB) | wall time (s) | peak / the shortest log's |"
  echo "|---|---|---|---|"
} >"$summary"
base=""
for rows in "${lengths[@]}"; do
  d="$out/rows$rows"
  if [[ ! -s "$d/logs/manifest.json" && ! -d "$d/logs/train" ]]; then
    echo "recording $rows rows ..." >&2
    rm -rf "$d" && mkdir -p "$d"
    "$hadynet" collect --object Cylinder --motion random2 --init 1 --rows "$rows" --seed 12 --out "$d/logs" --quiet >/dev/null
  fi
  /usr/bin/time -f "%M %e" -o "$d/time.txt" "$hadynet" residual "$model" "$d/logs" --horizon 50 --pb state \
    --json "$d/residual.json" >"$d/out.txt" 2>"$d/err.txt"
  read -r kb seconds <"$d/time.txt"
  mb=$((kb / 1024))
  [[ -n "$base" ]] || base=$mb
  echo "| $rows | $mb | $seconds | $(python3 -c "print(f'{$mb / $base:.2f}')") |" >>"$summary"
  tail -1 "$summary" >&2
done
cat "$summary"

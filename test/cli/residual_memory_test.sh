#!/usr/bin/env bash
# Issue 12 ("residual on 40 000 rows at horizon 50 uses 1.9 GB"): the
# residual analysis runs in memory that does not grow with the log's length.
# One hand log of 1 000 and one of 4 000 rows (Cylinder random2 init 1, seed
# 12), each analysed at horizon 50 with its state's trained PB; the peak
# resident memory of each run is read with getrusage. The bound: the longer
# log may take at most 60 MB more than the shorter. Measured with the
# chunked passes (bench/residual_memory.sh, docs/residual.md "Memory on long
# logs": 61 MB at 2 500 rows, 71 MB at 10 000) the growth is a few MB per
# 1 000 rows; before them every window's predictions were held at once,
# 498 MB at 2 500 rows and 2 000 MB at 10 000, about 200 MB more per 1 000
# rows, so 3 000 rows more would have grown by about 600 MB.
#   residual_memory_test.sh HADYNET MODEL WORKDIR
set -uo pipefail
hadynet=$1 model=$2 work=$3
rm -rf "$work" && mkdir -p "$work" || exit 2
peak_mb=()
for rows in 1000 4000; do
  "$hadynet" collect --object Cylinder --motion random2 --init 1 --rows "$rows" --seed 12 --out "$work/rows$rows" \
    --quiet >/dev/null || { echo "FAIL: collect $rows rows"; exit 1; }
  mb=$(python3 - "$hadynet" "$model" "$work/rows$rows" <<'PY'
import resource, subprocess, sys
hadynet, model, logs = sys.argv[1:]
run = subprocess.run([hadynet, "residual", model, logs, "--horizon", "50", "--pb", "state"],
                     stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
if run.returncode != 0:
    sys.exit("residual failed: " + run.stderr.strip()[-300:])
print(resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss // 1024)  # kB on Linux
PY
  ) || { echo "FAIL: $mb"; exit 1; }
  echo "$rows rows at horizon 50: peak resident memory $mb MB"
  peak_mb+=("$mb")
done
growth=$((peak_mb[1] - peak_mb[0]))
if ((growth > 60)); then
  echo "FAIL: 3 000 more rows took $growth MB more (bound 60 MB): memory grows with the log"
  exit 1
fi
echo "ok: 3 000 more rows took $growth MB more (bound 60 MB)"

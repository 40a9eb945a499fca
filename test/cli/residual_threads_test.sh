#!/usr/bin/env bash
# `hadynet residual --fix` gives the same bytes with any --threads: the
# network's passes run on the trainer's work pool, whose chunks fall on
# Eigen's register blocks (docs/trainer.md, "Threads"), so the thread count
# must change no prediction, no fine-tuned weight and no decision. A plant
# set with the cross-talk fc1 -> fc0 (seed 4861, 300 rows; a development set
# of the tie-break, docs/residual.md) through --fix with 1 and with 2
# threads; the JSON files must be equal byte for byte (no tolerance: the
# contract is bit-identity). The second run must say it ran on 2 threads
# (so an option that did nothing would fail), and the run must have applied
# a fine-tuned plan (its loss history holds every epoch) so the comparison
# covers the pool's backward passes. 4 fine-tuning epochs instead of 20 and
# 2 candidates instead of 5 keep it short: the passes are the same code at
# any count of either. The network alone is checked at 1 to 5 threads by
# WorkPool.NetworkResultsDoNotDependOnTheThreadCount.
#   residual_threads_test.sh HADYNET MODEL WORKDIR
set -uo pipefail
hadynet=$1 model=$2 work=$3
here=$(cd "$(dirname "$0")/../.." && pwd)
source "$here/test/cli/plant_fix_run.sh"
epochs=4
plant_fix_run "$hadynet" "$model" "$work" 4861 --threads 1 --fix-epochs $epochs --candidates 2 -- --effect crosstalk=0.35 || exit 1
mv "$work/residual.json" "$work/threads1.json"
"$hadynet" residual "$model" "$work/logs" --rated-range fc=0..50 --rated-range f=0..200 --fix --threads 2 \
  --fix-epochs $epochs --candidates 2 --json "$work/threads2.json" >"$work/out2.txt" 2>&1 || { echo "FAIL: residual --threads 2"; exit 1; }
grep -q "the network's passes on 2 threads" "$work/out2.txt" || { echo "FAIL: --threads 2 did not say it ran on 2 threads"; exit 1; }
grep -q "the network's passes on" "$work/out.txt" && { echo "FAIL: --threads 1 said it ran on more threads"; exit 1; }
python3 - "$work/threads1.json" $epochs <<'PY' || exit 1
import json, sys
fix = json.load(open(sys.argv[1]))["fix"]
history = fix.get("loss_history") or []
if len(history) != int(sys.argv[2]) or not fix.get("candidates"):
    sys.exit("FAIL: --fix applied no plan fine-tuned for %s epochs (%d losses, %d candidates)"
             % (sys.argv[2], len(history), len(fix.get("candidates") or [])))
print("fine-tuned %d epochs, %d candidates, status %s" % (len(history), len(fix["candidates"]), fix.get("status")))
PY
if ! cmp "$work/threads1.json" "$work/threads2.json"; then
  echo "FAIL: --threads 1 and --threads 2 wrote different JSON"
  diff <(python3 -m json.tool "$work/threads1.json") <(python3 -m json.tool "$work/threads2.json") | head -20
  exit 1
fi
echo "ok: --threads 1 and 2 wrote the same JSON"

#!/usr/bin/env bash
# HADYNET on measured data nobody here produced: the public Cascaded Tanks
# benchmark (../shared/data/cascaded-tanks, Schoukens, Mattsson, Wigren, Noel
# 2016). Imports both records, trains on the estimation record only, and
# measures on the validation record (its own initial state, never seen in
# training; nothing is tuned on it: every setting is a default):
#   * free-run simulation RMSE from the record's first state with its pump
#     input only, with the trained PB and with a PB adapted to the record,
#     next to the published range for good nonlinear models (0.3-0.6 V);
#   * the residual loop (`hadynet residual --fix`) on the validation record,
#     and what it finds about the overflow at 10 V (the level sensor's rail):
#     the rows at the rail, the model's own highest prediction, the rail
#     hypotheses; and friction on the pump voltage's change (the logs
#     declare u an absolute input: absolute_groups=u).
# Data sets: training = the estimation record's first 90 % of windows (seed
# 1); the residual loop's null = the rest of the estimation record, which
# train holds out and stores in the model (no training window touches it);
# measurement = the validation record. No threshold is calibrated here.
#
# Usage: scripts/cascaded_tanks.sh [OUT]      (default OUT: build/cascaded-tanks)
# Environment: HADYNET (default build/release/cli/hadynet), DATA (the CSV),
# EPOCHS (default 200, the trainer's default).
# Writes OUT/summary.txt (also printed), the logs, the model and
# OUT/residual/REPORT.md. Exit status: 0 done, 1 a step failed.
set -euo pipefail
case "${1:-}" in -h | --help) sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'; exit 0 ;; esac
cd "$(dirname "$0")/.."
out="${1:-build/cascaded-tanks}"
hadynet="${HADYNET:-build/release/cli/hadynet}"
data="${DATA:-../shared/data/cascaded-tanks/dataBenchmark.csv}"
epochs="${EPOCHS:-200}"
[[ -x "$hadynet" ]] || { echo "cascaded_tanks: $hadynet not found (scripts/build.sh release)" >&2; exit 1; }
[[ -r "$data" ]] || { echo "cascaded_tanks: $data not readable" >&2; exit 1; }
rm -rf "$out" && mkdir -p "$out/train"
summary="$out/summary.txt"

echo "[1/4] import" >&2
"$hadynet" import "$data" --out "$out/train/est.csv" --column uEst=u0 --column yEst=y0 --dt 4 --state tanks \
  --meta "units=t=s u=V y=V" --meta absolute_groups=u >&2
"$hadynet" import "$data" --out "$out/val.csv" --column uVal=u0 --column yVal=y0 --dt 4 --state tanks \
  --meta "units=t=s u=V y=V" --meta absolute_groups=u >&2
echo "[2/4] train ($epochs epochs on the estimation record)" >&2
"$hadynet" train "$out/train" --out "$out/tanks.safetensors" --epochs "$epochs" --seed 1 --quiet >&2
echo "[3/4] free-run simulation of the validation record" >&2
rmse() { sed -n 's/^  y \+\([0-9.eE+-]*\)$/\1/p' <<<"$1"; }
trained=$("$hadynet" simulate "$out/tanks.safetensors" --log "$out/val.csv" --out "$out/sim_trained.csv" --pb tanks)
adapted=$("$hadynet" simulate "$out/tanks.safetensors" --log "$out/val.csv" --out "$out/sim_adapted.csv" --pb adapt)
echo "[4/4] residual loop on the validation record" >&2
"$hadynet" residual "$out/tanks.safetensors" "$out/val.csv" --fix \
  --report "$out/residual" > "$out/residual.txt" 2>&1

{
  echo "Cascaded Tanks (HADYNET, $epochs epochs, seed 1; trained on the estimation record only)"
  echo "free-run RMSE on the validation record (V): trained PB $(rmse "$trained"), adapted PB $(rmse "$adapted")" \
       "($(grep -o 'step halved [0-9]* times' <<<"$adapted" || echo 'step not halved')); published good nonlinear models: 0.3-0.6"
  python3 - "$out" <<'PY'
import csv, json, sys
out = sys.argv[1]
def column(path, name):
    with open(path) as f:
        rows = [l for l in f if not l.startswith("#")]
    r = list(csv.DictReader(rows))
    return [float(x[name]) for x in r]
for rec in ("train/est.csv", "val.csv"):
    y = column(f"{out}/{rec}", "y0")
    at = [i for i, v in enumerate(y) if v >= 9.99]
    print(f"{rec}: {len(at)} of {len(y)} rows at the 10 V rail" + (f" (rows {at[0]}..{at[-1]})" if at else ""))
sim = column(f"{out}/sim_trained.csv", "y0")
print(f"free-run prediction (trained PB) peaks at {max(sim):.2f} V")
j = json.load(open(f"{out}/residual/residual.json"))
print("residual " + j["attribution"]["floors"])
print("residual verdict:", j["verdict"])
for h in j["attribution"]["ranked"]:
    # The rail, and friction on the pump voltage's change (an absolute input: absolute_groups=u).
    if h["effect"] in ("saturation", "friction"):
        print(f"  {h['label']}: testable {h['testable']}, held-out explained {h['explained']:.3f}, p(Holm) {h['p_adjusted']:.2g}")
fix = j.get("fix", {})
print("fix:", fix.get("status", "-"))
PY
} | tee "$summary"

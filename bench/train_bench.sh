#!/usr/bin/env bash
# Benchmark (not a test): seconds per training epoch on the paper preset
# (17 604 windows of 10 steps, batch 100, hidden 128, PB 8), hadynet train
# (Eigen, this repository) against PyTorch 1.13 (Debian's python3-torch,
# bench/torch_baseline.py: the same network, windows, standardisation, Adam
# and batch size), both measured in this run on this machine. Reports the
# median epoch time of each and the ratio PyTorch / hadynet.
#
# Usage: bench/train_bench.sh [EPOCHS]     (default 3 epochs each; DATA=dir to
#        use another dataset folder; THREADS=n for both, default: all cores)
set -euo pipefail
cd "$(dirname "$0")/.."
epochs="${1:-3}"
data="${DATA:-data/paper}"
threads="${THREADS:-$(nproc)}"

scripts/setup.sh --bench
scripts/build.sh release >/dev/null
hadynet=build/release/cli/hadynet
if [[ ! -f "$data/manifest.json" ]]; then
  "$hadynet" collect --preset paper --out "$data"
fi
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT

median() { sort -g | awk '{v[NR]=$1} END {print (NR%2 ? v[(NR+1)/2] : (v[NR/2]+v[NR/2+1])/2)}'; }

echo "machine: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs), $(nproc) cores; threads $threads"
"$hadynet" train "$data/train" --out "$work/m.safetensors" --epochs "$epochs" --held-out 0 \
  --threads "$threads" --quiet >/dev/null
ours=$(tail -n +2 "$work/m.safetensors.loss.csv" | cut -d, -f4 | median)
"$hadynet" train "$data/train" --out "$work/m1.safetensors" --epochs "$epochs" --held-out 0 \
  --threads 1 --quiet >/dev/null
ours1=$(tail -n +2 "$work/m1.safetensors.loss.csv" | cut -d, -f4 | median)
/usr/bin/python3 bench/torch_baseline.py --data "$data" --epochs "$epochs" --threads "$threads" \
  --json "$work/torch.json" >/dev/null
torch=$(/usr/bin/python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['median_epoch_seconds'])" "$work/torch.json")
torch_version=$(/usr/bin/python3 -c "import torch; print(torch.__version__)")

printf 'hadynet train (%s threads): %.3f s/epoch\n' "$threads" "$ours"
printf 'hadynet train (1 thread):   %.3f s/epoch\n' "$ours1"
printf 'PyTorch %s (%s threads): %.3f s/epoch\n' "$torch_version" "$threads" "$torch"
awk -v t="$torch" -v o="$ours" 'BEGIN { printf "ratio PyTorch / hadynet: %.1fx\n", t / o }'

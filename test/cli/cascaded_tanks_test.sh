#!/usr/bin/env bash
# scripts/cascaded_tanks.sh in the suite (issue 12, "real data in the
# suite"): measured data nobody here produced goes through import, train,
# free-run simulation, PB adaptation and the residual loop.
# Tolerances: free-run RMSE on the validation record below 1.5 V (a model
# that learned nothing, the record's mean, scores its std, 2.10 V; the
# adaptation that diverged before the step safeguard scored 1.89 V; measured
# 0.88 V at 100 epochs on the development VM); the adapted PB within 15 % of
# the trained PB's RMSE (both fit the same system: measured 0.5 % apart).
#   cascaded_tanks_test.sh HADYNET WORKDIR
set -uo pipefail
hadynet=$1 work=$2
here="$(cd "$(dirname "$0")/../.." && pwd)"
data="$here/../shared/data/cascaded-tanks/dataBenchmark.csv"
[[ -r "$data" ]] || { echo "cascaded_tanks_test: $data missing (../shared is part of the test environment)"; exit 1; }
out=$(HADYNET="$hadynet" DATA="$data" EPOCHS=100 "$here/scripts/cascaded_tanks.sh" "$work" 2>&1) \
  || { echo "FAIL: the script failed"; echo "$out" | tail -20; exit 1; }
echo "$out" | tail -12
line=$(grep '^free-run RMSE' <<<"$out")
trained=$(sed -n 's/.*trained PB \([0-9.]*\),.*/\1/p' <<<"$line")
adapted=$(sed -n 's/.*adapted PB \([0-9.]*\) .*/\1/p' <<<"$line")
[[ -n "$trained" && -n "$adapted" ]] || { echo "FAIL: no RMSE in: $line"; exit 1; }
python3 - "$trained" "$adapted" <<'PY' || exit 1
import sys
t, a = map(float, sys.argv[1:])
ok = t < 1.5 and a < 1.5 and a <= 1.15 * t
print(f"trained {t} V, adapted {a} V: {'ok' if ok else 'FAIL'}")
sys.exit(0 if ok else 1)
PY
grep -q "rows at the 10 V rail" <<<"$out" && grep -q "^residual verdict:" <<<"$out" || { echo "FAIL: no overflow/verdict lines"; exit 1; }
# A hypothesis whose fit over-predicts the held-out rows (a negative
# explained share) is labelled so on stdout, never listed like an effect
# beside its p-value (issue 12: negative shares beside p = 1e-201). The
# validation record has such hypotheses (a curve of y0 at -0.16 with
# p(Holm) 6e-15), so the check is not empty.
negative=$(grep -E '^    .* explained +-[0-9]' "$work/residual.txt")
[[ -n "$negative" ]] || { echo "FAIL: no hypothesis with a negative share to check"; exit 1; }
while IFS= read -r line; do
  [[ "$line" == *"over-predicts held out" ]] || { echo "FAIL: a negative share without its label: $line"; exit 1; }
done <<<"$negative"
# What the loop says of the overflow at 10 V: the rail tested, or why not
# with its evidence (issue 12: before, only "not testable: a regressor is
# constant in the training part", which said nothing of the data).
grep -Eq "^  upper rail of y0 at 10 .*(testable True|not testable: the 1-step prediction passes the rail in [0-9]+ of [0-9]+ training rows)" <<<"$out" \
  || { echo "FAIL: the 10 V rail without a test or its evidence: $(grep '^  upper rail' <<<"$out")"; exit 1; }
# The loop's floors on real data come from a calibrated null: the estimation
# record's held-out rows stored in the model (before: absolute floors set on
# the hand, two orders of magnitude above this model's whole residual).
grep -q "^residual floors: calibrated null of 1 reference logs (the model's held-out logs" <<<"$out" \
  || { echo "FAIL: the residual loop had no calibrated null: $(grep '^residual floors' <<<"$out")"; exit 1; }
# The pump voltage is a level (the logs declare absolute_groups: u): friction
# on its change is tested (before: "not testable", sign(u) of a voltage that
# never crosses 0 being constant).
grep -q "^  friction on y0 with the motion of u0 (absolute: its change): .*testable True" <<<"$out" \
  || { echo "FAIL: friction on the pump voltage's change was not tested: $(grep '^  friction' <<<"$out")"; exit 1; }

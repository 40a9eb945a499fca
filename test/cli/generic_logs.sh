#!/usr/bin/env bash
# Issue 12 ("hand defaults break other logs"): `hadynet train` on (u, y) logs
# that are not the hand's, with the defaults. Before: the default
# --delta-groups l,th failed on logs without an `l` group, and
# `--delta-groups none` was read as a group name. Now the delta groups come
# from the logs' `delta_groups` metadata (none when absent).
#   generic_logs.sh HADYNET WORKDIR
set -uo pipefail
hadynet=$1 work=$2
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 2
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }

# Two logs of a damped spring driven by u0: observed groups `pos` and `vel`.
python3 - <<'PY'
import math
def log(path, seed, extra=""):
    with open(path, "w") as f:
        f.write("# format: hadynet-log\n# format_version: 1\n# dt_s: 0.1\n# state: s%d\n%s" % (seed, extra))
        f.write("t,pos0,vel0,u0\n")
        p = v = 0.0
        for r in range(120):
            u = math.sin(0.3 * r + seed)
            f.write("%.1f,%.6f,%.6f,%.6f\n" % (0.1 * r, p, v, u))
            v += 0.1 * (u - 2.0 * p - 0.5 * v)
            p += 0.1 * v
log("a.csv", 1)
log("b.csv", 2)
log("c.csv", 3, "# delta_groups: pos\n")
PY
mkdir -p plain tagged mixed
cp a.csv b.csv plain/
cp c.csv tagged/
cp a.csv c.csv mixed/
small=(--epochs 1 --batch 10 --window 3 --hidden 8 --pb-size 2 --quiet)

# Defaults on logs without an `l` group: trains (exit 0), no delta group.
out=$("$hadynet" train plain --out plain.safetensors "${small[@]}" 2>&1) || fail "train with defaults: $out"
[[ -s plain.safetensors ]] || fail "train with defaults wrote no model"
# `none` is no delta group, not a group called "none".
out=$("$hadynet" train plain --out none.safetensors --delta-groups none "${small[@]}" 2>&1) || fail "--delta-groups none: $out"
# The logs' metadata names them: the model's x has dpos0.
out=$("$hadynet" train tagged --out tagged.safetensors "${small[@]}" 2>&1) || fail "train tagged: $out"
grep -qa 'dpos0' tagged.safetensors || fail "the tagged logs' delta group is not in the model's x"
grep -qa 'dpos0' plain.safetensors && fail "untagged logs got a delta group"
# Logs that disagree: refused, naming the log and the way out.
out=$("$hadynet" train mixed --out mixed.safetensors "${small[@]}" 2>&1); status=$?
[[ $status -eq 1 ]] || fail "mixed metadata: exit $status, expected 1"
[[ "$out" == *"c.csv: metadata 'delta_groups' is 'pos' but absent in"*"give --delta-groups"* ]] || fail "mixed metadata message: $out"
# An explicit list still names a group the logs lack.
out=$("$hadynet" train plain --out x.safetensors --delta-groups l "${small[@]}" 2>&1); status=$?
[[ $status -eq 1 && "$out" == *"delta group 'l' is not an observed channel group"* ]] || fail "--delta-groups l: exit $status: $out"

# The residual loop on them, with --fix: every printed figure is a number or
# "-" (before: "fine-tune nan  after nan" when nothing was fixed), and the PB
# each log used is said in words (before: "PB auto" while a PB was adapted).
out=$("$hadynet" residual plain.safetensors plain --fix --fix-epochs 1 2>&1); status=$?
[[ $status -eq 0 ]] || fail "residual --fix: exit $status: $(head -3 <<<"$out")"
grep -qiE '(^|[^a-z])-?nan([^a-z]|$)' <<<"$out" && fail "residual printed NaN: $(grep -iE 'nan' <<<"$out" | head -2)"
grep -q "^--pb auto: 2 logs with their state's trained PB$" <<<"$out" || fail "no PB summary line: $(head -3 <<<"$out")"
out=$("$hadynet" residual plain.safetensors tagged 2>&1); status=$?
[[ $status -eq 0 ]] || fail "residual on an unknown state: exit $status: $(head -3 <<<"$out")"
grep -q "with a PB adapted to their state's logs (states the model was not trained on)" <<<"$out" \
  || fail "an adapted PB was not said: $(head -3 <<<"$out")"

# The null: the model stores its training logs' held-out rows, and the
# residual loop calibrates its floors on them by default (before: absolute
# floors set on the hand, whatever the data). Logs under test that hold those
# rows (here the training logs themselves) cannot be their own null.
python3 - <<'PY'
import math
with open("d.csv", "w") as f:
    f.write("# format: hadynet-log\n# format_version: 1\n# dt_s: 0.1\n# state: s1\nt,pos0,vel0,u0\n")
    p = v = 0.0
    for r in range(120):
        u = math.cos(0.21 * r)
        f.write("%.1f,%.6f,%.6f,%.6f\n" % (0.1 * r, p, v, u))
        v += 0.1 * (u - 2.0 * p - 0.5 * v)
        p += 0.1 * v
PY
out=$("$hadynet" residual plain.safetensors d.csv 2>&1); status=$?
[[ $status -eq 0 ]] || fail "residual with the stored null: exit $status: $(tail -3 <<<"$out")"
grep -q "^floors: calibrated null of 2 reference logs (the model's held-out logs" <<<"$out" \
  || fail "the stored held-out logs are not the null: $(grep floors <<<"$out")"
out=$("$hadynet" residual plain.safetensors plain 2>&1)
grep -q "^floors: no calibrated null (every held-out log stored in the model is part of a log under test" <<<"$out" \
  || fail "the training logs were their own null: $(grep floors <<<"$out")"
# Logs under test with an aux_* column the stored logs lack: the null would
# test other hypotheses, so there is none, said (before: the run failed).
sed 's/^t,pos0,vel0,u0$/t,pos0,vel0,u0,aux_x/; /^[0-9]/s/$/,0.5/' d.csv >d_aux.csv
out=$("$hadynet" residual plain.safetensors d_aux.csv 2>&1); status=$?
[[ $status -eq 0 ]] || fail "residual with an aux column: exit $status: $(tail -2 <<<"$out")"
grep -q "^floors: no calibrated null (the model's held-out logs have other aux_\* columns" <<<"$out" \
  || fail "aux columns: $(grep '^floors' <<<"$out")"
out=$("$hadynet" residual plain.safetensors d.csv --reference none 2>&1)
grep -q "^floors: no calibrated null (--reference none)" <<<"$out" || fail "--reference none: $(grep floors <<<"$out")"
"$hadynet" train plain --out all.safetensors --held-out 0 "${small[@]}" >/dev/null 2>&1 || fail "train --held-out 0"
out=$("$hadynet" residual all.safetensors d.csv 2>&1)
grep -q "^floors: no calibrated null (the model stores no held-out logs" <<<"$out" \
  || fail "a model without held-out logs: $(grep floors <<<"$out")"
out=$("$hadynet" residual all.safetensors d.csv --min-excess-null 2 2>&1); status=$?
[[ $status -eq 2 && "$out" == *"--min-excess-null needs a null"* ]] || fail "--min-excess-null without a null: $status $out"

# Measured timestamps with jitter (issue 12: rejected with no way in):
# `hadynet import --time` resamples steps within --max-jitter of the median
# onto a regular grid and writes a log that validates; a lost sample (a step
# of twice the median) is an error naming its line.
python3 - <<'PY'
import math
with open("jitter.csv", "w") as f:
    f.write("time,position,command\n")
    for r in range(200):
        t = 0.1 * r + 0.004 * math.sin(1.7 * r)  # +-4 % of the 0.1 s step
        f.write("%.5f,%.6f,%.6f\n" % (t, math.sin(0.05 * r), math.cos(0.03 * r)))
with open("lost.csv", "w") as f:
    f.write("time,position,command\n")
    for r in [r for r in range(50) if r != 20]:
        f.write("%.2f,%.6f,%.6f\n" % (0.1 * r, math.sin(0.05 * r), math.cos(0.03 * r)))
PY
out=$("$hadynet" import jitter.csv --out jitter_log.csv --time time --column position=y0 --column command=u0 2>&1) \
  || fail "import --time of jittered timestamps: $out"
out=$("$hadynet" validate jitter_log.csv 2>&1) || fail "the resampled log does not validate: $out"
out=$("$hadynet" import lost.csv --out lost_log.csv --time time --column position=y0 --column command=u0 2>&1); status=$?
[[ $status -eq 1 && "$out" == *"lost.csv:22:"*"a lost sample"* ]] || fail "a lost sample: exit $status: $out"

echo "generic_logs: $failures failed"
[[ $failures -eq 0 ]]

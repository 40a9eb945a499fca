#!/usr/bin/env bash
# `hadynet residual` with bad arguments and bad inputs (issue 18): every case
# ends with its exit code (2: usage error, 1: a failure; docs/residual.md,
# "Exit codes"), a message that names the problem (the option, the file, and
# for a malformed log its line and column), no C++ exception text, no output
# file, and within 30 s (each case takes well under 1 s on the development VM).
#   residual_bad_args.sh HADYNET MODEL WORKDIR
set -uo pipefail
hadynet=$1 model=$2 work=$3
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 2
failures=0

# expect CODE PHRASE ARGS...: `hadynet residual ARGS` exits CODE with PHRASE
# in its output, writes neither out.json nor the report folder.
expect() {
  local code=$1 phrase=$2; shift 2
  local out status
  rm -rf out.json report
  out=$(timeout 30 "$hadynet" residual "$@" 2>&1); status=$?
  if [[ $status -eq 124 ]]; then echo "FAIL (timeout) residual $*"; failures=$((failures + 1)); return; fi
  if [[ $status -ne $code ]]; then
    echo "FAIL (exit $status, expected $code) residual $*"; echo "$out" | head -5; failures=$((failures + 1)); return
  fi
  if [[ "$out" != *"$phrase"* ]]; then
    echo "FAIL (message) residual $*"; echo "  expected: $phrase"; echo "$out" | head -5 | sed 's/^/  got: /'
    failures=$((failures + 1)); return
  fi
  if grep -qE "terminate called|std::|what\(\)|basic_string|stod|stof|json\.exception" <<<"$out"; then
    echo "FAIL (exception text in the output) residual $*"; echo "$out" | head -5; failures=$((failures + 1)); return
  fi
  if [[ -e out.json || -e report ]]; then
    echo "FAIL (an output was written) residual $*"; failures=$((failures + 1)); return
  fi
  echo "ok: residual $* -> $(head -1 <<<"$out" | cut -c1-150)"
}

# Logs with the hand's channels (the build's model reads them): a good one,
# one with a non-number in row 11 (file line 15, column 12: f2), one without
# the model's fc8, one shorter than the analysis needs.
python3 - <<'PY'
hdr = "# format: hadynet-log\n# format_version: 1\n# dt_s: 0.2\n"
names = ["t"] + [f"l{i}" for i in range(8)] + [f"f{i}" for i in range(8)] + [f"fc{i}" for i in range(9)] + \
        ["th0", "th1"] + [f"u{i}" for i in range(8)]
def hand_log(path, rows=60, bad=None, drop=None):
    cols = [n for n in names if n != drop]
    with open(path, "w") as f:
        f.write(hdr + ",".join(cols) + "\n")
        for r in range(rows):
            v = [repr(round(0.2 * r, 6))] + [repr(round(0.01 * ((r * 7 + c * 3) % 11), 3)) for c in range(1, len(cols))]
            if bad and r == bad[0]:
                v[cols.index(bad[1])] = bad[2]
            f.write(",".join(v) + "\n")
hand_log("good.csv")
hand_log("malformed.csv", bad=(10, "f2", "abc"))
hand_log("no_fc8.csv", drop="fc8")
hand_log("short.csv", rows=8)
PY
mkdir -p logs && cp good.csv malformed.csv logs/

# The good log is analysed (exit 0, the JSON written): each bad case below
# differs from this run by the one thing its message names. Without a null
# (--reference none): the default null, the model's 36 held-out logs, adapts
# a PB per trained state to check it, 6 min under ASan on 2 cores.
if ! timeout 60 "$hadynet" residual "$model" good.csv --reference none --json out.json >good.out 2>&1 || [[ ! -s out.json ]]; then
  echo "FAIL: the good log is not analysed"; head -5 good.out; failures=$((failures + 1))
fi

# Usage errors: exit 2, the option or the missing argument named.
expect 2 "give MODEL and logs"
expect 2 "give MODEL and logs" "$model"
expect 2 "unknown option '--frobnicate'" "$model" good.csv --frobnicate
expect 2 "option '--alpha' needs a value" "$model" good.csv --json out.json --alpha
expect 2 "--alpha: expected a number in 1e-12..0.5, got '2'" "$model" good.csv --json out.json --alpha 2
expect 2 "--crosstalk-sources must be unit, group or all, not 'near'" "$model" good.csv --json out.json --crosstalk-sources near
expect 2 "--horizon: expected a whole number in 1..1000, got '0'" "$model" good.csv --json out.json --horizon 0
expect 2 "--out needs --fix" "$model" good.csv --out fixed.safetensors
expect 2 "--rounds needs --fix" "$model" good.csv --rounds 2 --json out.json
expect 2 "--rated-range: rated range 'fc=5..1': LOW must be below HIGH" "$model" good.csv --rated-range fc=5..1 --json out.json
expect 2 "expected NAME=LOW..HIGH" "$model" good.csv --rated-range fc --json out.json
expect 1 "rated range 'u': no output channel or group of that name" "$model" good.csv --rated-range u=0..1 --json out.json
expect 2 "--min-excess-null needs a null (not --reference none)" "$model" good.csv --reference none --min-excess-null 2 --json out.json
expect 2 "--min-excess-null: expected a number" "$model" good.csv --reference good.csv --min-excess-null x --json out.json
expect 2 "--fix-min-excess-null needs --fix" "$model" good.csv --fix-min-excess-null 1 --json out.json
expect 2 "--fix-min-excess-null needs a null (not --reference none)" "$model" good.csv --reference none --fix \
  --fix-min-excess-null 1 --json out.json
expect 2 "--fix-min-excess-null: expected a number in 0..1e+06, got '1e9'" "$model" good.csv --fix \
  --fix-min-excess-null 1e9 --json out.json
expect 2 "--fix-folds: expected a whole number in 1..2, got '3'" "$model" good.csv --fix --fix-folds 3 --json out.json
expect 2 "--decision-loss is squared or absolute, not 'cubic'" "$model" good.csv --fix --decision-loss cubic \
  --json out.json
expect 2 "--decision-scale is std or residual, not 'relative'" "$model" good.csv --fix --decision-scale relative \
  --json out.json
expect 2 "--decision-pooling is rows or logs, not 'folds'" "$model" good.csv --fix --decision-pooling folds \
  --json out.json
expect 2 "--fix-selection is screen-order or every-channel, not 'best'" "$model" good.csv --fix --fix-selection best \
  --json out.json
expect 2 "--fix-tie-break is largest-gain or fewest-channels, not 'simplest'" "$model" good.csv --fix \
  --fix-tie-break simplest --json out.json
expect 2 "--fix-min-excess-null 4 is above the screen's --min-excess-null 3" "$model" good.csv --fix \
  --fix-min-excess-null 4 --json out.json
expect 2 "--fix-upper-rail-floor needs --fix" "$model" good.csv --fix-upper-rail-floor 0 --json out.json
expect 2 "--fix-upper-rail-floor needs a null (not --reference none)" "$model" good.csv --reference none --fix \
  --fix-upper-rail-floor 0 --json out.json
expect 2 "--fix-upper-rail-floor: expected a number in 0..1e+06, got '-1'" "$model" good.csv --fix \
  --fix-upper-rail-floor -1 --json out.json
expect 2 "--fix-upper-rail-floor 1.5 is above the candidates' floor 1" "$model" good.csv --fix \
  --fix-upper-rail-floor 1.5 --json out.json
expect 2 "--fix-upper-rail-floor 0.6 is above the candidates' floor 0.5" "$model" good.csv --fix \
  --fix-min-excess-null 0.5 --fix-upper-rail-floor 0.6 --json out.json
expect 2 "--fix-upper-rail-floor 0.6 is above the candidates' floor 0.5" "$model" good.csv --fix \
  --min-excess-null 0.5 --fix-upper-rail-floor 0.6 --json out.json
expect 1 "--reference good.csv is also a log under test" "$model" good.csv --reference good.csv --json out.json
expect 1 "no_fc8.csv: no column 'fc8'" "$model" good.csv --reference no_fc8.csv --json out.json
expect 1 "malformed.csv:15:12: column 'f2'" "$model" good.csv --reference malformed.csv --json out.json
# Failures: exit 1, the file named.
expect 1 "missing.safetensors: cannot read safetensors file" missing.safetensors good.csv --json out.json
expect 1 "good.csv: header length" good.csv good.csv --json out.json
expect 1 "missing_logs: no such file or folder" "$model" missing_logs --json out.json
expect 1 "malformed.csv:15:12: column 'f2': expected a finite number, got 'abc'" "$model" malformed.csv --json out.json
expect 1 "logs/malformed.csv:15:12: column 'f2'" "$model" logs --report report
expect 1 "no_fc8.csv: no column 'fc8'" "$model" no_fc8.csv --json out.json
expect 1 "short.csv: 8 rows; at least 13 needed" "$model" short.csv --json out.json
expect 1 "PB 'nonsense'" "$model" good.csv --pb nonsense --json out.json
[[ -e fixed.safetensors ]] && { echo "FAIL: fixed.safetensors written"; failures=$((failures + 1)); }

echo "residual_bad_args: $failures failed"
[[ $failures -eq 0 ]]

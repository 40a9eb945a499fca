#!/usr/bin/env bash
# bench/residual_twin_cut.sh, the driver, with a stand-in for hadynet (a
# script that writes a twin's JSON; the clean twin's logs are there
# already, so nothing is recorded): a set's line and the table, the twin's
# run once and then reused, the model key (another model, or other rows,
# refused; twins without a key refused), and bad arguments (exit 2 with
# the problem named). The numbers are residual_twin_cut_test.py's first
# set: cut 0.300, twin 0.250.
#   residual_twin_cut_sh_test.sh WORKDIR
set -uo pipefail
work=$1
here=$(cd "$(dirname "$0")/../.." && pwd)
script="$here/bench/residual_twin_cut.sh"
rm -rf "$work" && mkdir -p "$work/bench/tension-leak=0.2/seed7" "$work/out/clean/seed7" || exit 2
fail() { echo "FAIL: $*"; exit 1; }
python3 - "$work" <<'PY'
import json, sys
def rmse(v, samples=480):
    return {"samples": samples, "channels": [{"channel": c, "rmse": x} for c, x in v.items()]}
work = sys.argv[1]
fix = {"train_fraction": 0.6, "changed": True,
       "augmentation": {"effect": "crosstalk", "channels": ["fc6"], "source": "f5", "gain": 0.2,
                        "description": "remove the crosstalk f5 -> fc6"},
       "confirmation": {"channels": ["fc6"]},
       "before": rmse({"fc6": 0.4}), "after": rmse({"fc6": 0.12}), "control": rmse({"fc6": 0.3})}
json.dump({"fix": fix}, open(f"{work}/bench/tension-leak=0.2/seed7/residual.json", "w"))
json.dump({"fix": {"changed": False, "before": rmse({"fc6": 0.14}), "control": rmse({"fc6": 0.1})}},
          open(f"{work}/twin.json", "w"))
PY
printf 'a model\n' >"$work/model-a" && printf 'another model\n' >"$work/model-b"
# The stand-in: `residual MODEL LOGS ... --json PATH`: copies the twin's JSON to PATH and counts its runs.
cat >"$work/hadynet" <<SH
#!/usr/bin/env bash
[[ \$1 == residual ]] || exit 3
echo run >>"$work/runs"
while ((\$#)); do [[ \$1 == --json ]] && cp "$work/twin.json" "\$2"; shift; done
SH
chmod +x "$work/hadynet"
run() { HADYNET="$work/hadynet" bash "$script" "$@" >"$work/stdout" 2>"$work/stderr"; }

run --out "$work/out" --model "$work/model-a" "$work/bench" || fail "first run exited $?: $(cat "$work/stderr")"
grep -qx "tension-leak=0.2 seed 7: bar yes named yes cut yes 0.300 twin 0.250 (unchanged model 0.350) within yes (on 1 channels)" \
  "$work/out/lines.txt" || fail "the line: $(cat "$work/out/lines.txt")"
grep -q "| tension-leak=0.2 | 1 | 1 | 0 | 0 (-) | 0 | 0.250 | - |" "$work/out/summary.txt" || fail "the table: $(cat "$work/out/summary.txt")"
[[ -f "$work/out/twin/seed7.json" && ! -e "$work/out/twin/seed7.json.part" ]] || fail "the twin's JSON"
run --out "$work/out" --model "$work/model-a" "$work/bench" || fail "second run exited $?"
[[ $(wc -l <"$work/runs") -eq 1 ]] || fail "the twin was run again: $(wc -l <"$work/runs") runs"

run --out "$work/out" --model "$work/model-b" "$work/bench"
[[ $? -eq 2 ]] && grep -q "another model's or row count's twins" "$work/stderr" || fail "another model: $(cat "$work/stderr")"
RESIDUAL_ROWS=600 run --out "$work/out" --model "$work/model-a" "$work/bench"
[[ $? -eq 2 ]] && grep -q "another model's or row count's twins" "$work/stderr" || fail "other rows: $(cat "$work/stderr")"
rm "$work/out/twin/model.txt"
run --out "$work/out" --model "$work/model-a" "$work/bench"
[[ $? -eq 2 ]] && grep -q "twins without model.txt" "$work/stderr" || fail "no key: $(cat "$work/stderr")"

run --out
[[ $? -eq 2 ]] && grep -q -- "--out needs a value" "$work/stderr" || fail "--out without a value: $(cat "$work/stderr")"
run --out "$work/o2" --model "$work/model-a" "$work/nowhere"
[[ $? -eq 2 ]] && grep -q "is not a directory" "$work/stderr" || fail "a missing BENCH_OUT: $(cat "$work/stderr")"
run --out "$work/o2" --model "$work/no-model" "$work/bench"
[[ $? -eq 2 ]] && grep -q "not found" "$work/stderr" || fail "a missing model: $(cat "$work/stderr")"
run --frobnicate
[[ $? -eq 2 ]] && grep -q "unknown option" "$work/stderr" || fail "an unknown option: $(cat "$work/stderr")"
run --help || fail "--help exited $?"
[[ $(tail -n 1 "$work/stdout") == "the repository's), RESIDUAL_ROWS." ]] || fail "--help ends: $(tail -n 1 "$work/stdout")"
echo "all checks passed"

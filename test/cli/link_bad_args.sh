#!/usr/bin/env bash
# `hadynet link` with bad arguments or an unreachable device: exit 2 for a
# usage error, 1 for a device that cannot be reached, and a message that names
# the problem; never a hang (10 s per case; each returns at once).
#   link_bad_args.sh HADYNET
set -uo pipefail
hadynet=$1
failures=0

# expect CODE PHRASE ARGS...: `hadynet link ARGS` exits CODE with PHRASE in its output.
expect() {
  local code=$1 phrase=$2; shift 2
  local out status
  out=$(timeout 10 "$hadynet" link "$@" 2>&1); status=$?
  if [[ $status -ne $code ]]; then
    echo "FAIL (exit $status, expected $code) link $*"; echo "$out" | head -3; failures=$((failures + 1)); return
  fi
  if [[ "$out" != *"$phrase"* ]]; then
    echo "FAIL (message) link $*: expected '$phrase', got: $(head -1 <<<"$out")"; failures=$((failures + 1)); return
  fi
  echo "ok: link $* -> $(head -1 <<<"$out")"
}

expect 2 "give one of --device, --tcp, --qemu and an ACTION"
expect 2 "give one of --device, --tcp, --qemu and an ACTION" info
expect 2 "give one of --device, --tcp, --qemu and an ACTION" --tcp 127.0.0.1:1 --device /dev/null info
expect 2 "--tcp needs HOST:PORT, not 'nohost'" --tcp nohost info
expect 2 "--numeric must be q15 or f32, not 'q16'" --numeric q16 --tcp 127.0.0.1:1 info
expect 2 "unknown option '--speed'" --speed 3 --tcp 127.0.0.1:1 info
# Port 1 on the loopback: nothing listens there on a test machine.
expect 1 "127.0.0.1:1: cannot connect" --tcp 127.0.0.1:1 info
expect 1 "/nonexistent/tty: cannot open" --device /nonexistent/tty info

if ((failures > 0)); then echo "$failures failure(s)"; exit 1; fi
echo "all cases pass"

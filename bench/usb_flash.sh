#!/usr/bin/env bash
# Firmware flashing and telemetry through the USB testbed (not a test;
# docs/usb.md). Host and protocol cost, not the MCU's: the "device" is the
# simulated STM32 ROM DfuSe bootloader (test/dfuse_sim) and the hand
# (test/usb_host/hand_device.h) served to real libusb clients by umockdev.
#
# Runs usb_flash_bench (test/usb_host/usb_flash_bench.cc) under
# umockdev-wrapper, which times child processes:
#   * `hadynet flash IMAGE` (erase, write, read back and compare, leave)
#     against `dfu-util -a 0 -s 0x08000000:leave -D IMAGE` (erase, write,
#     leave; no verify: the baseline, measured in the same run, runs
#     alternating), REPS runs each, every run on a fresh bootloader whose
#     flash is checked against the image. IMAGE is a pseudo-random .bin of
#     the size of the stm32f405 hadynet-firmware image (346 732 bytes,
#     docs/boards.md; the cross build is not needed). The sim reports
#     bwPollTimeout at POLL_PERCENT % of the datasheet's worst case (default
#     0: no device waits, host and protocol only); the table adds what the
#     datasheet figures (sector erase 800..4000 ms, 25 us/byte programming)
#     would add on a real F405, from the sim's own sum of them.
#   * a model update: a signed image of the build's model (this build's
#     `hadynet model-image`) into the hand's slot not in use through its DFU
#     model interface, `hadynet flash --model IMAGE` (send, read back and
#     compare) against `dfu-util -i 4 -a 0 -D IMAGE`; the table adds the
#     bwPollTimeouts a real F405 asks for (the firmware's poll rule with the
#     datasheet's times, docs/usb.md: a block that starts a 128 KiB sector
#     4007 ms, any other 7 ms, the header check 250 ms, the manifest 2000 ms).
#   * `hadynet monitor`: latency from the publish of a telemetry record (one
#     in flight) to its line on monitor's stdout, and records/s when the next
#     record is published as soon as the host has taken the previous one.
#
# Usage: bench/usb_flash.sh [BUILD_DIR]
#   BUILD_DIR: a host build with usb_flash_bench and hadynet built (default
#   build/release; e.g. cmake --build build/release --target usb_flash_bench).
# Environment: REPS (default 3), POLL_PERCENT (default 0), BYTES (default
# 346732), RECORDS (default 200).
# Exit status: 0 done, 1 the benchmark failed, 2 usage / driver not found.
set -euo pipefail

usage() { sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'; }
case "${1:-}" in
  -h | --help) usage; exit 0 ;;
  -*) echo "usb_flash: unknown option $1" >&2; usage >&2; exit 2 ;;
esac
[[ $# -le 1 ]] || { usage >&2; exit 2; }
cd "$(dirname "$0")/.."

build="${1:-build/release}"
driver="$build/test/usb_host/usb_flash_bench"
if [[ ! -x "$driver" ]]; then
  echo "usb_flash: $driver not found (build the target usb_flash_bench)" >&2
  exit 2
fi
command -v umockdev-wrapper >/dev/null || { echo "usb_flash: umockdev-wrapper not installed" >&2; exit 2; }
reps="${REPS:-3}"; poll="${POLL_PERCENT:-0}"; bytes="${BYTES:-346732}"; records="${RECORDS:-200}"

out=$(umockdev-wrapper "$driver" --reps "$reps" --poll-percent "$poll" --bytes "$bytes" --records "$records") || {
  echo "usb_flash: the benchmark failed (exit $?):" >&2
  echo "$out" >&2
  exit 1
}
grep -q '^end' <<<"$out" || { echo "usb_flash: the benchmark did not finish:" >&2; echo "$out" >&2; exit 1; }

echo "machine: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs), $(nproc) cores; $(uname -sr)"
echo "clients: $build/cli/hadynet (this build), $(dfu-util -V 2>/dev/null | head -1)"
awk '
  function field(line, key,   i, kv, n, parts) {
    n = split(line, parts, " ")
    for (i = 1; i <= n; ++i) { split(parts[i], kv, "="); if (kv[1] == key) return kv[2] }
    return ""
  }
  function median(list, n,   i, j, t, a) {
    for (i = 1; i <= n; ++i) a[i] = list[i]
    for (i = 1; i <= n; ++i) for (j = i + 1; j <= n; ++j) if (a[j] < a[i]) { t = a[i]; a[i] = a[j]; a[j] = t }
    return n % 2 ? a[(n + 1) / 2] : (a[n / 2] + a[n / 2 + 1]) / 2
  }
  /^bench / { bytes = field($0, "bytes"); reps = field($0, "reps"); poll = field($0, "poll_percent") }
  /^flash / {
    tool = field($0, "tool"); n[tool]++
    s[tool, n[tool]] = field($0, "seconds"); ds[tool] = field($0, "datasheet_poll_ms"); sec[tool] = field($0, "sectors")
  }
  /^model / {
    mtool = field($0, "tool"); mn[mtool]++
    ms[mtool, mn[mtool]] = field($0, "seconds"); mbytes = field($0, "bytes")
  }
  /^latency / { lat = $0 }
  /^throughput / { thr = $0 }
  END {
    printf "\nFlash %d bytes (pseudo-random .bin at 0x08000000, the size of the stm32f405 image) through the\n", bytes
    printf "simulated ROM DfuSe bootloader, wTransferSize 2048; bwPollTimeout at %d %% of the datasheet; median of %d runs\n", poll, reps
    printf "(wall time of the client process: start-up, enumeration, every transfer; dfu-util is the baseline)\n\n"
    printf "%-9s %-26s %8s %8s %9s %11s %12s %8s\n", "client", "does", "s", "kB/s", "ratio", "sectors", "+datasheet", "= s"
    for (k = 0; k < 2; ++k) {
      tool = k == 0 ? "dfu-util" : "hadynet"
      for (i = 1; i <= n[tool]; ++i) l[i] = s[tool, i]
      m[tool] = median(l, n[tool])
    }
    base = m["dfu-util"]
    for (k = 0; k < 2; ++k) {
      tool = k == 0 ? "dfu-util" : "hadynet"
      what = k == 0 ? "erase, write, leave" : "erase, write, verify, leave"
      add = ds[tool] / 1000.0 * (100 - poll) / 100.0
      printf "%-9s %-26s %8.3f %8.1f %8.2fx %11d %11.1fs %8.1f\n", tool, what, m[tool], bytes / m[tool] / 1000,
             m[tool] / base, sec[tool], add, m[tool] + add
    }
    printf "\n+datasheet: the worst-case bwPollTimeouts a real F405 would add (the sim sums them: sector erases and\n"
    printf "25 us/byte programming), less the share already slept at %d %%; both clients sleep what the device asks.\n", poll
    blocks = int((mbytes + 255) / 256); sectors = int((mbytes - 256 + 1024 + 131071) / 131072)
    mds = (sectors * 4000 + blocks * 7 + 250 + 2000) * 0.99  # the hand already waits 1 % of it
    printf "\nModel update: a %d-byte signed image of the build\47s model into the hand\47s slot not in use (DFU model\n", mbytes
    printf "interface, wTransferSize 256; the hand\47s flash waits are 1 %% of the F405\47s); median of %d runs\n\n", reps
    printf "%-9s %-26s %8s %8s %9s %12s %8s\n", "client", "does", "s", "kB/s", "ratio", "+datasheet", "= s"
    for (k = 0; k < 2; ++k) {
      tool = k == 0 ? "dfu-util" : "hadynet"
      for (i = 1; i <= mn[tool]; ++i) l[i] = ms[tool, i]
      mm[tool] = median(l, mn[tool])
    }
    for (k = 0; k < 2; ++k) {
      tool = k == 0 ? "dfu-util" : "hadynet"
      what = k == 0 ? "send" : "send, read back, compare"
      printf "%-9s %-26s %8.3f %8.1f %8.2fx %11.1fs %8.1f\n", tool, what, mm[tool], mbytes / mm[tool] / 1000,
             mm[tool] / mm["dfu-util"], mds / 1000.0, mm[tool] + mds / 1000.0
    }
    printf "\n+datasheet: %d blocks, %d sector erases at 4000 ms, 7 ms per block, 250 ms header check, 2000 ms manifest\n", blocks, sectors
    printf "(the firmware\47s worst-case bwPollTimeouts on a real F405, which both clients sleep), less the 1 %% the\n"
    printf "hand already waits.\n"
    printf "\nTelemetry through `hadynet monitor` (hidapi libusb backend; 4 x 64-byte HID reports per record)\n\n"
    printf "%-34s %10s %10s %10s\n", "", "median", "p90", "max"
    printf "%-34s %8.2fms %8.2fms %8.2fms\n", "latency publish -> stdout line (" field(lat, "records") ")",
           field(lat, "median_ms"), field(lat, "p90_ms"), field(lat, "max_ms")
    rs = field(thr, "records") / field(thr, "seconds")
    printf "%-34s %10.0f records/s = %.0f reports/s (the real device: 5 records/s)\n", "throughput (" field(thr, "records") " back to back)", rs, 4 * rs
  }' <<<"$out"

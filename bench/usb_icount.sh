#!/usr/bin/env bash
# What the USB device stack adds per control period, in instructions counted
# by QEMU (not a test; docs/usb.md, "Benchmark").
#
# Runs the image hadynet-bench-usb (firmware/app/bench_usb.cc) of mps2-an386
# under `-icount shift=0`, where every instruction takes exactly 1 ns of
# virtual time, so the 25 MHz SysTick advances once per 40 instructions. The
# image runs the firmware's 5 Hz loop with the composite USB device over the
# fake controller, whose host side plays the USB host: a muscle state per
# period over CDC-ACM, the period record as HID telemetry. Prints
# instructions per period of the period's runtime work (the baseline, detect
# and control mode) and of the USB device side (service, publish, controller
# events), the ratio of the two measured in the same run, and the flash and
# RAM of the USB stack in that image (symbol sizes of the ELF).
#
# Usage: bench/usb_icount.sh [IMAGE_DIR]
#   IMAGE_DIR: images/ of a cross build (default build/cortex-m4/images; build
#   it with cmake --preset cortex-m4 (after the release build: its codegen)
#   && cmake --build --preset cortex-m4 --target mps2-an386-bench-usb).
# Environment: QEMU (default qemu-system-arm), OBJDUMP (default
# arm-none-eabi-objdump).
# Exit status: 0 done, 1 the benchmark failed, 2 usage / image not found.
set -euo pipefail

usage() { sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'; }
case "${1:-}" in
  -h | --help) usage; exit 0 ;;
  -*) echo "usb_icount: unknown option $1" >&2; usage >&2; exit 2 ;;
esac
[[ $# -le 1 ]] || { usage >&2; exit 2; }
cd "$(dirname "$0")/.."

images="${1:-build/cortex-m4/images}"
qemu="${QEMU:-qemu-system-arm}"
objdump="${OBJDUMP:-arm-none-eabi-objdump}"
elf="$images/mps2-an386/hadynet-bench-usb.elf"
if [[ ! -f "$elf" ]]; then
  echo "usb_icount: $elf not found (build the target mps2-an386-bench-usb of a cortex-m4 build)" >&2
  exit 2
fi

out=$(timeout 600 "$qemu" -M mps2-an386 -nographic -monitor none -serial stdio \
        -semihosting-config enable=on,target=native -icount shift=0 -kernel "$elf" </dev/null) || {
  echo "usb_icount: the benchmark failed (exit $?):" >&2
  echo "$out" >&2
  exit 1
}
if ! grep -q '^end' <<<"$out"; then
  echo "usb_icount: the benchmark did not finish:" >&2
  echo "$out" >&2
  exit 1
fi

# Instructions per rep = (ticks - timings x the empty pair's ticks) x 1e9 / tick_hz / reps.
awk '
  function field(line, key,   i, kv, n, parts) {
    n = split(line, parts, " ")
    for (i = 1; i <= n; ++i) { split(parts[i], kv, "="); if (kv[1] == key) return kv[2] }
    return ""
  }
  /^bench / { hz = field($0, "tick_hz"); periods = field($0, "periods") }
  /^job / {
    name = field($0, "name")
    reps[name] = field($0, "reps"); ticks[name] = field($0, "ticks"); timings[name] = field($0, "timings")
  }
  /^check / { check = $0 }
  /^memory / { memory = $0 }
  function per_rep(name) { return (ticks[name] - timings[name] * pair) * ipt / reps[name] }
  function row(label, name, value, what) {
    printf "%-16s %5d  %16.0f  %s\n", label, reps[name], value, what
  }
  END {
    ipt = 1e9 / hz
    pair = ticks["ticks_overhead"] / timings["ticks_overhead"]
    printf "USB device stack per control period: instructions under QEMU -icount shift=0\n"
    printf "(mps2-an386, hadynet-bench-usb.elf, q15; 1 SysTick tick = %.0f instructions; %d timed periods per mode;\n", ipt, periods
    printf " each timing'"'"'s own ticks() cost, %.0f instructions, subtracted)\n\n", pair * ipt
    printf "%-16s %5s  %16s  %s\n", "job", "reps", "instructions/rep", "what"
    detect = per_rep("period_detect"); control = per_rep("period_control")
    service = per_rep("usb_service"); publish = per_rep("usb_publish"); events = per_rep("usb_events")
    link = per_rep("link"); usb = service + publish + events
    row("period_detect", "period_detect", detect, "run_period + end_period, detect mode (baseline)")
    row("period_control", "period_control", control, "run_period + end_period, control mode (baseline)")
    row("usb_service", "usb_service", service, "the period'"'"'s 4 usb.service() calls: CDC bytes -> link -> bulk IN")
    row("  link share", "link", link, "  of which the link itself (COBS, CRC-32, dispatch; the UART pays it too)")
    row("usb_publish", "usb_publish", publish, "usb.publish(record): 4 HID reports encoded, first IN started")
    row("usb_events", "usb_events", events, "UsbDevice::handle() of the 7 controller events (3 CDC, 4 HID)")
    row("usb (device)", "usb_service", usb, "service + publish + events")
    row("host (fake)", "host", per_rep("host"), "the fake controller'"'"'s host side: simulation, not counted above")
    row("service_idle", "service_idle", per_rep("service_idle"), "one usb.service() with nothing to do (each further main-loop pass)")
    printf "\nUSB device side / period work:  detect %.2f %%, control %.3f %%\n", 100 * usb / detect, 100 * usb / control
    printf "without the link share:         detect %.2f %%, control %.3f %%\n", 100 * (usb - link) / detect, 100 * (usb - link) / control
    printf "%s\n", check
  }' <<<"$out"

# Flash and RAM of the stack in this image, from the ELF's symbol table.
printf '\nUSB stack in hadynet-bench-usb.elf (bytes; %s -t: sizes of the symbols of namespace\n' "$objdump"
printf 'hadynet::usb and of hadynet::flash::FlashRegionWriter (DFU), without usb::host:: (the fake controller),\n'
printf 'the host-side TelemetryDecoder and SimulatedNorFlash (the board'"'"'s drivers take their place: not counted);\n'
printf 'flash = .text + .rodata, RAM = .data + .bss of those + the HadynetUsbDevice object; code inlined into the\n'
printf 'benchmark'"'"'s own functions (publish) and unnamed string literals are not counted)\n\n'
"$objdump" -t -C "$elf" | awk -v memory="$(grep '^memory ' <<<"$out")" '
  BEGIN { FS = "\t" }
  function hex(s,   i, v) {  # mawk has no strtonum
    v = 0
    for (i = 1; i <= length(s); ++i) v = v * 16 + index("0123456789abcdef", tolower(substr(s, i, 1))) - 1
    return v
  }
  NF >= 2 {
    n = split($1, left, " "); section = left[n]; addr = left[1]
    size = hex(substr($2, 1, index($2, " ") - 1)); name = substr($2, index($2, " ") + 1)
    if (name == "(anonymous namespace)::g_usb") { device = size; next }
    sub(/^(vtable for |non-virtual thunk to |guard variable for )/, "", name)
    sub(/^(void|bool|unsigned int|std::size_t) /, "", name)
    if (seen[addr section]++) next  # constructor aliases share an address
    if (name ~ /^hadynet::usb::(host::|TelemetryDecoder)/ || name ~ /^hadynet::flash::SimulatedNorFlash/) next
    if (name ~ /^hadynet::usb::CdcAcm/) part = "CdcAcm (CDC-ACM)"
    else if (name ~ /^hadynet::usb::(HidTelemetry|encode_telemetry)/) part = "HidTelemetry (HID)"
    else if (name ~ /^hadynet::usb::DfuRuntime/) part = "DfuRuntime"
    else if (name ~ /^(hadynet::usb::Dfu|hadynet::flash::)/) part = "DfuMode + FlashRegionWriter"
    else if (name ~ /^hadynet::usb::(UsbDevice|UsbFunction)/) part = "UsbDevice (EP0, ch. 9)"
    else if (name ~ /^hadynet::usb::/) part = "HadynetUsbDevice, descriptors"
    else next
    if (section == ".text") text[part] += size
    else if (section == ".rodata") rodata[part] += size
    else if (section == ".data" || section == ".bss") ram[part] += size
  }
  END {
    printf "%-30s %8s %8s %8s\n", "part", "text", "rodata", "RAM"
    n = split("UsbDevice (EP0, ch. 9)|CdcAcm (CDC-ACM)|HidTelemetry (HID)|DfuRuntime|DfuMode + FlashRegionWriter|" \
              "HadynetUsbDevice, descriptors", order, "|")
    for (i = 1; i <= n; ++i) {
      p = order[i]
      printf "%-30s %8d %8d %8d\n", p, text[p], rodata[p], ram[p]
      t += text[p]; r += rodata[p]; d += ram[p]
    }
    printf "%-30s %8s %8s %8d\n", "HadynetUsbDevice object (g_usb)", "", "", device
    printf "%-30s %8d %8d %8d\n", "total", t, r, d + device
    printf "flash %d bytes, RAM %d bytes\n", t + r, d + device
    k = split(memory, m, /[ =]/)
    for (i = 2; i < k; i += 2) size_of[m[i]] = m[i + 1]
    printf "sizeof (the image): HadynetUsbDevice %d = UsbDevice %d + CdcAcm %d + HidTelemetry %d + DfuMode %d + DfuRuntime %d + ...\n",
      size_of["usb_device"], size_of["usb_core"], size_of["cdc"], size_of["hid"], size_of["dfu_mode"], size_of["dfu_runtime"]
    printf "stack used %d of %d bytes (the whole benchmark)\n", size_of["stack_used"], size_of["stack"]
  }'

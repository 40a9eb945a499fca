#!/usr/bin/env python3
"""Runs a firmware image in qemu-system-arm for a CTest test (test/boards/).

The image's serial port is QEMU's stdio; semihosting is on, so the image's
exit code (board::exit) is QEMU's. A conversation is a list of steps, each
"send a line (optional), then wait until the output matches a regular
expression"; afterwards the runner waits for QEMU to exit and checks the exit
code. Every wait is bounded: on --timeout the whole QEMU process group is
killed and the test fails with the transcript so far.

  qemu_run.py --machine mps2-an386 --kernel image.elf \\
      --step 'ping' 'pong mps2-an386 q15 [0-9a-f]{16}' \\
      --step 'exit 3' - --exit-code 3

"-" stands for "nothing" in a step (send nothing / wait for nothing).

--retry-first resends the first step's line every half second until its
pattern appears (netduinoplus2 drops bytes that arrive before the firmware
has enabled its USART). --expect-from-command CMD... runs a host program
first and waits for its first output line, literally, in QEMU's output
(the runtime checksum test).
"""

import argparse
import os
import re
import select
import signal
import subprocess
import sys
import time


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--qemu", default="qemu-system-arm")
    parser.add_argument("--machine", required=True)
    parser.add_argument("--kernel", required=True)
    parser.add_argument("--icount", action="store_true", help="-icount shift=0 (one instruction per ns)")
    parser.add_argument("--step", nargs=2, action="append", default=[], metavar=("SEND", "EXPECT"),
                        help="line to send ('-': none), then a regular expression to wait for ('-': none)")
    parser.add_argument("--retry-first", action="store_true")
    parser.add_argument("--expect-from-command", nargs=argparse.REMAINDER, default=None)
    parser.add_argument("--exit-code", type=int, default=0)
    parser.add_argument("--timeout", type=float, default=20.0, help="seconds for the whole run")
    args = parser.parse_args()

    if not os.path.isfile(args.kernel):
        print(f"qemu_run: image not found: {args.kernel}\n"
              "  build the firmware images first (cortex-m4 preset; scripts/test.sh does)", file=sys.stderr)
        return 2

    steps = [("" if send == "-" else send, "" if expect == "-" else expect) for send, expect in args.step]
    if args.expect_from_command:
        host = subprocess.run(args.expect_from_command, capture_output=True, text=True, timeout=args.timeout)
        if host.returncode != 0 or not host.stdout.strip():
            print(f"qemu_run: {' '.join(args.expect_from_command)} failed ({host.returncode}):\n{host.stderr}",
                  file=sys.stderr)
            return 2
        expected_line = host.stdout.strip().splitlines()[0]
        print(f"qemu_run: host says: {expected_line}")
        steps.append(("", re.escape(expected_line)))

    command = [args.qemu, "-M", args.machine, "-nographic", "-monitor", "none", "-serial", "stdio",
               "-semihosting-config", "enable=on,target=native", "-kernel", args.kernel]
    if args.icount:
        command[1:1] = ["-icount", "shift=0"]
    print("qemu_run: " + " ".join(command))
    qemu = subprocess.Popen(command, stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                            start_new_session=True)
    deadline = time.monotonic() + args.timeout
    transcript = bytearray()

    def kill() -> None:
        try:
            os.killpg(qemu.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
        qemu.wait()

    def fail(reason: str) -> int:
        kill()
        print(f"qemu_run: FAIL: {reason}\n--- serial output ---\n{transcript.decode(errors='replace')}\n---")
        return 1

    def read_some(limit: float) -> str:
        """Reads what QEMU printed within `limit` seconds: "data", "idle" or "eof"."""
        ready, _, _ = select.select([qemu.stdout], [], [], max(0.0, limit))
        if not ready:
            return "idle"
        chunk = os.read(qemu.stdout.fileno(), 4096)
        if not chunk:
            return "eof"
        transcript.extend(chunk)
        return "data"

    def send(line: str) -> None:
        qemu.stdin.write(line.encode() + b"\n")
        qemu.stdin.flush()

    searched_from = 0
    for index, (line, pattern) in enumerate(steps):
        retry = args.retry_first and index == 0 and line
        if line:
            send(line)
        last_send = time.monotonic()
        regex = re.compile(pattern.encode()) if pattern else None
        while regex is not None:
            match = regex.search(transcript, searched_from)
            if match:
                searched_from = match.end()
                break
            now = time.monotonic()
            if now > deadline:
                return fail(f"timeout after {args.timeout:.0f} s waiting for /{pattern}/")
            if retry and now - last_send > 0.5:
                send(line)
                last_send = now
            if read_some(min(0.2, deadline - now)) == "eof":
                return fail(f"QEMU ended (exit code {qemu.wait()}) before /{pattern}/ appeared")

    # Then the program must end by itself, with the expected exit code.
    qemu.stdin.close()
    while qemu.poll() is None:
        now = time.monotonic()
        if now > deadline:
            return fail(f"timeout after {args.timeout:.0f} s waiting for QEMU to exit")
        if read_some(min(0.2, deadline - now)) == "eof":
            break
    try:
        code = qemu.wait(timeout=max(0.1, deadline - time.monotonic()))
    except subprocess.TimeoutExpired:
        return fail("QEMU did not exit")
    while read_some(0) == "data":
        pass
    print(transcript.decode(errors="replace"))
    if code != args.exit_code:
        print(f"qemu_run: FAIL: exit code {code}, expected {args.exit_code}")
        return 1
    print(f"qemu_run: ok (exit code {code})")
    return 0


if __name__ == "__main__":
    sys.exit(main())

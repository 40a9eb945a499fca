#!/usr/bin/env python3
"""Instructions per function of a firmware image run under QEMU (not a test;
docs/boards.md, "Where the control period goes").

Reads QEMU's `-d in_asm,exec,nochain` log on stdin: every translated block
with its instructions ("IN:" listings) and every execution of a block
("Trace" lines). A block's executions times its instruction count, summed
over the blocks that start inside a function of the ELF's symbol table, are
that function's instructions (inlined code counts for its caller).

--between SYMBOL N: count only what runs from the N-th to the (N+1)-th
entry into SYMBOL (for the benchmark image: Bench<...>::report is entered
once per job, so N = 2 is the control_full job: its warm-up period and its
timed periods, plus the N-th report's few hundred instructions).

Run it without -icount: under -icount QEMU translates shortened blocks at the
end of each instruction budget, and a block's listing would no longer be the
one that ran.
"""
import argparse
import bisect
import collections
import re
import subprocess
import sys


def symbols(elf):
    out = subprocess.run(["arm-none-eabi-nm", "-C", "-S", "--defined-only", elf],
                         capture_output=True, text=True, check=True).stdout
    table = []
    for line in out.splitlines():
        parts = line.split(None, 3)
        if len(parts) == 4 and parts[2] in "tTwW":
            table.append((int(parts[0], 16) & ~1, int(parts[1], 16), parts[3]))
    table.sort()
    return table


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("elf", help="the image QEMU ran (its symbols)")
    parser.add_argument("--between", nargs=2, metavar=("SYMBOL", "N"),
                        help="count only between the N-th and (N+1)-th entry into the function whose "
                             "demangled name starts with SYMBOL")
    parser.add_argument("--top", type=int, default=25, help="functions to print (default 25)")
    args = parser.parse_args()

    table = symbols(args.elf)
    starts = [s[0] for s in table]

    def function(pc):
        i = bisect.bisect_right(starts, pc) - 1
        if i >= 0 and pc < table[i][0] + max(table[i][1], 2):
            return table[i][2]
        return "?0x%x" % pc

    marker = None
    if args.between:
        matches = [s for s in table if s[2].startswith(args.between[0])]
        if len(matches) != 1:
            sys.exit("qemu_profile: %d functions start with %r" % (len(matches), args.between[0]))
        marker, window = matches[0][0], int(args.between[1])

    block_size = {}
    executions = collections.Counter()
    entries = 0
    listing_start, listing_count = None, 0
    in_listing = False
    for line in sys.stdin:
        if line.startswith("IN:"):
            in_listing, listing_start, listing_count = True, None, 0
            continue
        if in_listing:
            m = re.match(r"0x([0-9a-f]+):", line)
            if m:
                if listing_start is None:
                    listing_start = int(m.group(1), 16)
                listing_count += 1
            elif not line.strip() and listing_start is not None:
                block_size[listing_start] = listing_count
                in_listing = False
            continue
        if line.startswith("Trace"):
            # "Trace N: host [cs_base/pc/flags/...] name" (the pc unpadded
            # from QEMU 8.1 on).
            m = re.search(r"\[([0-9a-f]+)/([0-9a-f]+)/", line)
            if not m:
                continue
            pc = int(m.group(2), 16)
            if marker is not None:
                if pc == marker:
                    entries += 1
                if entries != window:
                    continue
            executions[pc] += 1

    if marker is not None and entries < window:
        sys.exit("qemu_profile: %s was entered %d times, fewer than %d" % (args.between[0], entries, window))
    if not executions:
        sys.exit("qemu_profile: no executed blocks in the trace")
    per_function = collections.Counter()
    for pc, n in executions.items():
        per_function[function(pc)] += n * block_size.get(pc, 1)
    total = sum(per_function.values())
    print("instructions %d" % total)
    for name, n in per_function.most_common(args.top):
        print("%12d %5.1f %%  %s" % (n, 100.0 * n / max(total, 1), name[:110]))


if __name__ == "__main__":
    main()

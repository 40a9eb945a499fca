#!/usr/bin/env python3
"""The model-update boot rule on the Cortex-M4 (QEMU netduinoplus2, the
stm32f405 firmware image): a signed model image placed in model slot A of the
emulated flash, pre-marked tried and confirmed (QEMU does not emulate flash
programming, so the boot must not need to write a flag), is verified by the
firmware's own SHA-256 and Ed25519 at boot and runs: `hadynet link info`
reports that model's hash. The same image with one payload byte flipped, or
signed by another key, is refused on the MCU: the compiled-in model runs.

The model is the build's model file with one metadata entry added, so its
weights (and the self-test checksum) are the compiled-in model's but its
file hash differs: which model runs is told by the hash alone.

With --slot-only FILE it only writes the pre-confirmed slot of MODEL itself
(the replay test runs the firmware from it: replay_qemu.cmake's SLOT).

Usage: qemu_slot_boot.py --hadynet HADYNET --image ELF --model MODEL --key KEY --work DIR [--slot-only FILE]
"""
import argparse
import json
import os
import re
import struct
import subprocess
import sys

SLOT_A = 0x08080000
PAYLOAD_OFFSET = 1024
FLAGS = {256: 0x44595254, 272: 0x464E4F43}  # tried "TRYD", confirmed "CONF" (slot_layout.h)


def fnv1a64(data: bytes) -> int:
    h = 0xCBF29CE484222325
    for b in data:
        h = ((h ^ b) * 0x100000001B3) & 0xFFFFFFFFFFFFFFFF
    return h


def model_copy(src: str, dst: str) -> int:
    data = open(src, "rb").read()
    n = struct.unpack("<Q", data[:8])[0]
    header = json.loads(data[8:8 + n])
    header.setdefault("__metadata__", {})["note"] = "qemu slot boot test copy"
    text = json.dumps(header, separators=(",", ":")).encode()
    text += b" " * ((8 - len(text) % 8) % 8)
    out = struct.pack("<Q", len(text)) + text + data[8 + n:]
    open(dst, "wb").write(out)
    return fnv1a64(out)


def slot_file(image: bytes, dst: str) -> None:
    slot = bytearray(b"\xff" * (PAYLOAD_OFFSET + len(image) - 256))
    slot[0:256] = image[:256]
    for offset, magic in FLAGS.items():
        slot[offset:offset + 4] = struct.pack("<I", magic)
    slot[PAYLOAD_OFFSET:] = image[256:]
    open(dst, "wb").write(bytes(slot))


def info_hash(args, slot: str) -> int:
    out = subprocess.run([args.hadynet, "link", "--qemu", args.image, "--machine", "netduinoplus2",
                          "--qemu-load", f"{slot}@{SLOT_A:#x}", "info"],
                         capture_output=True, text=True, timeout=60)
    print(out.stdout.strip())
    if out.returncode != 0:
        sys.exit(f"hadynet link info failed ({out.returncode}): {out.stderr}")
    m = re.search(r"model hash ([0-9a-f]{16})", out.stdout)
    if not m:
        sys.exit("no model hash in: " + out.stdout)
    return int(m.group(1), 16)


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    for a in ("hadynet", "image", "model", "key", "work"):
        p.add_argument("--" + a, required=True)
    p.add_argument("--slot-only")
    args = p.parse_args()
    os.makedirs(args.work, exist_ok=True)
    if args.slot_only:
        path = os.path.join(args.work, "model.img")
        subprocess.run([args.hadynet, "model-image", args.model, "--key", args.key, "--sequence", "1", "--out", path],
                       check=True, capture_output=True)
        slot_file(open(path, "rb").read(), args.slot_only)
        return
    copy = os.path.join(args.work, "copy.safetensors")
    copy_hash = model_copy(args.model, copy)
    compiled_hash = fnv1a64(open(args.model, "rb").read())

    def make_image(key: str, name: str) -> bytes:
        path = os.path.join(args.work, name)
        subprocess.run([args.hadynet, "model-image", copy, "--key", key, "--sequence", "1", "--out", path],
                       check=True, capture_output=True)
        return open(path, "rb").read()

    good = make_image(args.key, "good.img")
    other_key = os.path.join(args.work, "other.key")
    for f in (other_key, other_key + ".pub"):
        if os.path.exists(f):
            os.remove(f)
    subprocess.run([args.hadynet, "keygen", "--out", other_key], check=True, capture_output=True)
    foreign = make_image(other_key, "foreign.img")
    flipped = bytearray(good)
    flipped[256 + len(good) // 2] ^= 0x10

    failures = []
    for name, image, want, what in (("good", good, copy_hash, "the slot's model"),
                                    ("flipped", bytes(flipped), compiled_hash, "the compiled-in model"),
                                    ("foreign", foreign, compiled_hash, "the compiled-in model")):
        slot = os.path.join(args.work, name + ".slot")
        slot_file(image, slot)
        got = info_hash(args, slot)
        verdict = "ok" if got == want else "WRONG"
        print(f"{name} image in slot A: model hash {got:016x}, want {what} {want:016x}: {verdict}")
        if got != want:
            failures.append(name)
    if failures:
        sys.exit("slot boot on the Cortex-M4 failed for: " + ", ".join(failures))
    print("slot boot on the Cortex-M4: the verified image runs, the corrupt and the foreign one do not")


if __name__ == "__main__":
    main()

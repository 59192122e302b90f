#!/usr/bin/env python3
"""The `text` of an ELF file as binutils' `size` counts it (every allocated section that is
neither writable nor NOBITS: code, read-only data, the vector table), and optionally a bound.

    python3 scripts/elf_size.py FILE [--max-text BYTES]

Stdlib only, so the test command needs no binutils; exits 1 when the text exceeds the bound.
"""
import argparse
import struct
import sys

SHF_WRITE, SHF_ALLOC = 0x1, 0x2
SHT_NOBITS = 8


def sizes(path):
    with open(path, "rb") as f:
        data = f.read()
    if data[:4] != b"\x7fELF":
        raise SystemExit(f"error: {path} is not an ELF file")
    is64 = data[4] == 2
    endian = "<" if data[5] == 1 else ">"
    if is64:
        shoff, = struct.unpack_from(endian + "Q", data, 0x28)
        shentsize, shnum = struct.unpack_from(endian + "HH", data, 0x3A)
    else:
        shoff, = struct.unpack_from(endian + "I", data, 0x20)
        shentsize, shnum = struct.unpack_from(endian + "HH", data, 0x2E)
    text = writable = bss = 0
    for i in range(shnum):
        base = shoff + i * shentsize
        if is64:
            _, kind, flags, _, _, size = struct.unpack_from(endian + "IIQQQQ", data, base)
        else:
            _, kind, flags, _, _, size = struct.unpack_from(endian + "IIIIII", data, base)
        if not flags & SHF_ALLOC:
            continue
        if kind == SHT_NOBITS:
            bss += size
        elif flags & SHF_WRITE:
            writable += size
        else:
            text += size
    return text, writable, bss


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("file")
    parser.add_argument("--max-text", type=int, help="fail when text exceeds this many bytes")
    args = parser.parse_args()
    text, data, bss = sizes(args.file)
    print(f"{args.file}: text {text} B, data {data} B, bss {bss} B")
    if args.max_text is not None and text > args.max_text:
        print(f"error: text {text} B exceeds the bound of {args.max_text} B", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())

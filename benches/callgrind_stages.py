#!/usr/bin/env python3
"""Splits callgrind's count of one control cycle by the core source file it was spent in.

LTO inlines the whole cycle into `tvmd_cycle_*` (examples/cycle_instructions.rs), so callgrind's
per-function view has one line; this script reads callgrind's per-instruction counts and, with
`addr2line -i` on a build with line tables, charges each instruction (and each call's inclusive
cost, at its call site) to the outermost `crates/tvmd-core/src` file other than controller.rs in
its inline chain (controller.rs lines otherwise): planner.rs = the planner, law.rs = validation
and the control law, allocation/ = the allocator, command.rs = the gimbal inverse of the
commands.

Usage (from the repository root; needs valgrind and binutils' addr2line):
  CARGO_PROFILE_RELEASE_DEBUG=line-tables-only cargo build --release --example cycle_instructions
  python3 benches/callgrind_stages.py target/release/examples/cycle_instructions tvmd_cycle_f64
"""

import collections
import re
import subprocess
import sys
import tempfile


def main() -> None:
    binary, function = sys.argv[1], sys.argv[2]
    with tempfile.NamedTemporaryFile(suffix=".out") as out:
        subprocess.run(
            ["valgrind", "--tool=callgrind", "--dump-instr=yes", "--compress-pos=no",
             "--compress-strings=no", f"--callgrind-out-file={out.name}",
             f"--toggle-collect={function}", binary],
            check=True, capture_output=True)
        # Self costs of instructions in the binary itself; a call into another object (libm)
        # is charged, inclusive, to its call site. Calls within the binary are not, as their
        # callee's instructions are counted themselves.
        cost: collections.Counter = collections.Counter()
        call_sites = set()
        ob = callee_ob = None
        after_call = False
        for line in open(out.name):
            if line.startswith("ob="):
                ob = line[3:].strip()
            elif line.startswith("cob="):
                callee_ob = line[4:].strip()
            elif line.startswith("calls="):
                after_call = True
            elif line.startswith("0x"):
                address, _line, count = line.split()[:3]
                ours = ob is not None and ob.endswith(binary.split("/")[-1])
                if after_call:
                    foreign = callee_ob is not None and callee_ob != ob
                    if ours and foreign:
                        cost[int(address, 16)] += int(count)
                        call_sites.add(int(address, 16))
                elif ours:
                    cost[int(address, 16)] += int(count)
                after_call = False
                callee_ob = None
    addresses = sorted(cost)
    lines = subprocess.run(
        ["addr2line", "-a", "-i", "-e", binary] + [hex(a) for a in addresses],
        check=True, capture_output=True, text=True).stdout.split("\n")
    chains: dict = {}
    at = None
    for line in lines:
        if re.match(r"^0x[0-9a-f]+$", line):
            at = int(line, 16)
            chains[at] = []
        elif line.startswith("/") and at is not None:
            chains[at].append(line)
    parts: collections.Counter = collections.Counter()
    for address, count in cost.items():
        core = [l for l in chains.get(address, []) if "/crates/tvmd-core/src/" in l]
        key = "(outside the core)"
        if not core and address in call_sites:
            continue  # e.g. _start's call into libc, which runs main: counted inside
        if core:
            stages = [l for l in core if "controller.rs" not in l]
            pick = stages[-1] if stages else core[-1]
            key = pick.split("/crates/tvmd-core/src/")[1]
            if "controller.rs" not in key:
                key = key.split(":")[0]
        parts[key] += count
    print(f"{function}: {sum(parts.values())} instructions")
    for key, count in parts.most_common():
        print(f"{count:8d}  {key}")


if __name__ == "__main__":
    main()

"""The criterion medians of `benches/allocation.rs` as a markdown table (us per allocation).

Run after `cargo bench --bench allocation --features clarabel -- ...`:
`python3 benches/allocation_table.py [CRITERION_DIR]` (default: $CARGO_TARGET_DIR/criterion or
target/criterion). Rows are teams, columns allocators, in the order criterion ran them.
"""

import json
import os
import pathlib
import sys


def main() -> None:
    default = pathlib.Path(os.environ.get("CARGO_TARGET_DIR", "target")) / "criterion"
    root = pathlib.Path(sys.argv[1]) if len(sys.argv) > 1 else default
    medians: dict[str, dict[str, float]] = {}
    allocators: list[str] = []
    for bench in sorted(root.glob("*/*/new/benchmark.json")):
        meta = json.loads(bench.read_text())
        group = meta.get("group_id", "")
        if not group.startswith("allocation/"):
            continue
        estimates = json.loads((bench.parent / "estimates.json").read_text())
        team = group.removeprefix("allocation/")
        name = meta["function_id"]
        medians.setdefault(team, {})[name] = estimates["median"]["point_estimate"] / 1e3
        if name not in allocators:
            allocators.append(name)
    if not medians:
        sys.exit(f"no allocation benchmarks under {root}")
    print("| team | " + " | ".join(allocators) + " |")
    print("|---|" + "---|" * len(allocators))
    for team, row in medians.items():
        cells = [f"{row[a]:.2f}" if a in row else "-" for a in allocators]
        print(f"| {team} | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()

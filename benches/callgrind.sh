#!/usr/bin/env bash
# Deterministic instruction counts of one full control cycle (n = 4) with callgrind.
# Counts only what runs inside each measured function (valgrind --toggle-collect), one call each.
# Usage: bash benches/callgrind.sh
set -euo pipefail
cd "$(dirname "$0")/.."
command -v valgrind >/dev/null || { echo "valgrind is not installed" >&2; exit 1; }
cargo build --release --example cycle_instructions
bin=target/release/examples/cycle_instructions
out=$(mktemp -d)
printf '%-28s %12s\n' "function" "instructions"
for f in tvmd_cycle_f32 tvmd_cycle_f64 tvmd_cycle_hover_f32; do
  valgrind --tool=callgrind --callgrind-out-file="$out/$f.out" --toggle-collect="$f" "$bin" >/dev/null 2>"$out/$f.log"
  ir=$(grep -E '^summary:|^totals:' "$out/$f.out" | head -1 | awk '{print $2}')
  printf '%-28s %12s\n' "$f" "$ir"
done
rm -rf "$out"

#!/usr/bin/env bash
# Footprint of the f32 control cycle on thumbv7em-none-eabihf (Cortex-M4F): section sizes of
# embedded/cycle-check (the whole program: team set-up + the cycle, no runtime) and the stack
# frame of its `_start`, into which LTO inlines the entire cycle.
# Usage: bash benches/footprint.sh
set -euo pipefail
cd "$(dirname "$0")/.."
rustup target add thumbv7em-none-eabihf >/dev/null
rustup component add llvm-tools >/dev/null 2>&1 || true
cargo build --release --manifest-path embedded/cycle-check/Cargo.toml --target thumbv7em-none-eabihf
bin=embedded/cycle-check/target/thumbv7em-none-eabihf/release/tvmd-cycle-check
tools="$(rustc --print sysroot)/lib/rustlib/$(rustc -vV | sed -n 's/host: //p')/bin"
"$tools/llvm-size" -A "$bin" | grep -E '^(section|\.text|\.rodata|\.data|\.bss)'
# Stack: pushes and `sub sp` in each function that can be live during the cycle.
"$tools/llvm-objdump" -d --demangle "$bin" | awk '
  function num(v,   i, d, r) { if (v !~ /^0x/) return v + 0; r = 0
    for (i = 3; i <= length(v); i++) { d = index("0123456789abcdef", substr(v, i, 1)) - 1; r = r * 16 + d }
    return r }
  /^[0-9a-f]+ <.*>:$/ { fn=$2; next }
  /\tpush(\.w)?\t/ { n=gsub(/r[0-9]+|lr/, "&"); push[fn]+=4*n }
  /\tvpush\t/ { m=gsub(/d[0-9]+/, "&"); push[fn]+=8*m; m=gsub(/s[0-9]+/, "&"); push[fn]+=4*m }
  /\tsub(\.w)?\tsp, (sp, )?#/ { match($0, /#(0x[0-9a-f]+|[0-9]+)/); v=substr($0, RSTART+1, RLENGTH-1); sub_[fn]+=num(v) }
  END { for (f in push) if (push[f]+sub_[f] > 0) printf "%8d bytes  %s\n", push[f]+sub_[f], f }' | sort -rn | head -8

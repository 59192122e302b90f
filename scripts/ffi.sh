#!/usr/bin/env bash
# The C interface (crates/tvmd-ffi, include/tvmd.h): the header compiles as C99 and C++11 with
# warnings as errors; the C test program, linked against the staticlib, runs the paper team
# (hover, the saturating tilt, failure masks, every error path, the actuator channel map) and
# the default offset-free law (law_test.c: convergence under an unmodelled force, the landed
# hold, bad law values), and its record is replayed on the Rust API bit for bit; a fuzz of the
# handle's storage (every word, several patterns) runs under a watchdog; the thumbv7em staticlib builds and every
# entry point links there without a panic path (embedded/ffi-check). The header's staleness is
# checked by `cargo test -p tvmd-ffi --test header` (part of `cargo test --workspace`).
# Installs a C/C++ compiler with apt-get where one is missing.
set -euo pipefail
cd "$(dirname "$0")/.."

step() { printf '\n==> %s\n' "$*"; }

export PYO3_BUILD_EXTENSION_MODULE=1
target_dir="${CARGO_TARGET_DIR:-target}"
case "$target_dir" in /*) ;; *) target_dir="$PWD/$target_dir" ;; esac
out="$target_dir/ffi"
mkdir -p "$out"

source scripts/lib/require.sh
require cc gcc
require c++ g++

step "include/tvmd.h compiles as C99 and as C++11 (-Wall -Wextra -Werror -pedantic)"
printf '#include "tvmd.h"\nint main(void) { return TVMD_ABI_VERSION == 5 ? 0 : 1; }\n' >"$out/header.c"
cp "$out/header.c" "$out/header.cpp"
cc -std=c99 -Wall -Wextra -Werror -pedantic -Iinclude -c "$out/header.c" -o "$out/header_c.o"
c++ -std=c++11 -Wall -Wextra -Werror -pedantic -Iinclude -c "$out/header.cpp" -o "$out/header_cpp.o"

step "C test program against the staticlib, then its record replayed on the Rust API"
cargo build --locked -p tvmd-ffi
cc -std=c99 -Wall -Wextra -Werror -pedantic -Iinclude crates/tvmd-ffi/tests/c/tvmd_test.c \
  crates/tvmd-ffi/tests/c/law_test.c crates/tvmd-ffi/tests/c/stages_test.c \
  crates/tvmd-ffi/tests/c/fault_test.c \
  "$target_dir/debug/libtvmd_ffi.a" -lm -lpthread -ldl -o "$out/tvmd_test"
"$out/tvmd_test" "$out/record.txt"
TVMD_FFI_C_RECORD="$out/record.txt" cargo test --locked -p tvmd-ffi --test c_record -- --ignored --nocapture

step "storage corruption: every word of a created handle overwritten, each case forked under a watchdog"
# crates/tvmd-ffi/tests/c/storage_fuzz.c: no entry point hangs (alarm) or crashes; every call
# returns TVMD_OK with finite outputs inside the created configuration's admissible set, or an
# error status (TVMD_ERR_CORRUPTED where a count, flag or enum tag is refused).
cc -std=c99 -D_POSIX_C_SOURCE=200809L -Wall -Wextra -Werror -pedantic -Iinclude \
  crates/tvmd-ffi/tests/c/storage_fuzz.c "$target_dir/debug/libtvmd_ffi.a" -lm -lpthread -ldl \
  -o "$out/storage_fuzz"
# Again against an optimized build (the ci profile: release without fat LTO), which may exploit
# what a stray write leaves (a tag assumed in range) where debug code does not: a hang in
# tvmd_step from the effectiveness blocks' tags showed only here (issue 57, item 7).
cargo build --locked -p tvmd-ffi --profile ci
cc -std=c99 -D_POSIX_C_SOURCE=200809L -Wall -Wextra -Werror -pedantic -Iinclude \
  crates/tvmd-ffi/tests/c/storage_fuzz.c "$target_dir/ci/libtvmd_ffi.a" -lm -lpthread -ldl \
  -o "$out/storage_fuzz_optimized"
"$out/storage_fuzz_optimized"
"$out/storage_fuzz"

step "the PX4 adapter include/tvmd_px4.hpp: C++17 test (-Wall -Wextra -Werror -Wpedantic -Wold-style-cast)"
c++ -std=c++17 -Wall -Wextra -Werror -Wpedantic -Wold-style-cast -Iinclude \
  crates/tvmd-ffi/tests/cpp/px4_test.cpp "$target_dir/debug/libtvmd_ffi.a" -lm -lpthread -ldl \
  -o "$out/px4_test"
"$out/px4_test"

step "the 4-agent capacity (feature capacity-4, TVMD_CAPACITY_4): the PX4 adapter's test and the storage fuzz again"
# Its own target directory: the feature changes the library's layout.
cargo build --locked -p tvmd-ffi --features capacity-4 --target-dir "$target_dir/capacity-4"
c++ -std=c++17 -Wall -Wextra -Werror -Wpedantic -Wold-style-cast -DTVMD_CAPACITY_4 -Iinclude \
  crates/tvmd-ffi/tests/cpp/px4_test.cpp "$target_dir/capacity-4/debug/libtvmd_ffi.a" -lm \
  -lpthread -ldl -o "$out/px4_test_capacity_4"
"$out/px4_test_capacity_4"
# The storage fuzz at this capacity (its own layout; about 30 s).
cc -std=c99 -D_POSIX_C_SOURCE=200809L -DTVMD_CAPACITY_4 -Wall -Wextra -Werror -pedantic -Iinclude \
  crates/tvmd-ffi/tests/c/storage_fuzz.c "$target_dir/capacity-4/debug/libtvmd_ffi.a" -lm \
  -lpthread -ldl -o "$out/storage_fuzz_capacity_4"
"$out/storage_fuzz_capacity_4"

step "staticlib for thumbv7em-none-eabihf (no_std) and its size"
cargo build --locked -p tvmd-ffi --no-default-features --target thumbv7em-none-eabihf --release
lib="$target_dir/thumbv7em-none-eabihf/release/libtvmd_ffi.a"
echo "libtvmd_ffi.a (thumbv7em-none-eabihf, release): $(wc -c <"$lib") bytes"

step "panic-free link check: every C entry point on thumbv7em with an undefined panic handler"
# Links only if no panic path survives (see embedded/ffi-check/src/main.rs).
# Its own target directory even when CARGO_TARGET_DIR is set: it builds tvmd-ffi with the
# link-check feature, whose libtvmd_ffi.a must not replace the one measured above.
check_dir=embedded/ffi-check/target
cargo build --release --locked --manifest-path embedded/ffi-check/Cargo.toml \
  --target thumbv7em-none-eabihf --target-dir "$check_dir"
echo "every entry point linked, opt-level 3 (the speed the on-target costs are measured at):"
python3 scripts/elf_size.py "$check_dir/thumbv7em-none-eabihf/release/tvmd-ffi-check"

step "the same link built for flash (opt-level z, LLVM inline threshold 40): panic-free too, text at most 81,000 B"
# Flight stacks build for size (PX4: -Os). At opt-level z alone nalgebra's small accessors stay
# out of line with their bounds checks (a panic path); an inline threshold of 40 inlines them
# back, and the link proves none is left. The flags go in CARGO_ENCODED_RUSTFLAGS so that they
# reach only this build. Its own target directory, so that neither build invalidates the other's
# cache. Issue 45 asked for at most 80 KB; the raw check of every tag the handle stores (issue 57,
# item 7) took it to 80,866 B, and the bound became 81,000 B: defined behaviour on a corrupted
# handle is worth 1.1% of flash (docs/c-interface.md, Footprint).
CARGO_PROFILE_RELEASE_OPT_LEVEL=z CARGO_ENCODED_RUSTFLAGS="-Cllvm-args=-inline-threshold=40" \
  cargo build --release --locked \
  --manifest-path embedded/ffi-check/Cargo.toml --target thumbv7em-none-eabihf \
  --target-dir embedded/ffi-check/target-flash
python3 scripts/elf_size.py embedded/ffi-check/target-flash/thumbv7em-none-eabihf/release/tvmd-ffi-check \
  --max-text 81000

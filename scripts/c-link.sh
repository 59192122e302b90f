#!/usr/bin/env bash
# tvmd's C interface linked into a bare-metal C program by arm-none-eabi-gcc, the way a
# Cortex-M4F flight stack links it: the staticlib (thumbv7em-none-eabihf, no default features),
# embedded/c-link/main.c (start-up code, a hover of 50 periods with the default controller),
# the linker script embedded/c-link/link.ld, no C library. Then it runs on QEMU's Cortex-M4F
# (mps2-an386) and Cortex-M7 (mps2-an500) boards and must exit with success; then the same with
# the library built for flash.
# Installs gcc-arm-none-eabi (about 50 MB, without recommends) with apt-get where it is missing;
# qemu-system-arm comes from scripts/target.sh, which the test command runs first.
set -euo pipefail
cd "$(dirname "$0")/.."

source scripts/lib/require.sh
source scripts/lib/qemu.sh
require arm-none-eabi-gcc gcc-arm-none-eabi
arm-none-eabi-gcc --version | head -n 1

rustup target add thumbv7em-none-eabihf
cargo build --locked -p tvmd-ffi --no-default-features --target thumbv7em-none-eabihf --release
target_dir="${CARGO_TARGET_DIR:-target}"
lib="$target_dir/thumbv7em-none-eabihf/release/libtvmd_ffi.a"
elf="$target_dir/c-link/tvmd-c-link.elf"
mkdir -p "$(dirname "$elf")"

# The flags a Cortex-M4F build of a flight stack uses (hard float: the staticlib's ABI), plus
# freestanding and no C library; --gc-sections drops the parts of the core no entry point uses.
flags=(-mcpu=cortex-m4 -mthumb -mfloat-abi=hard -mfpu=fpv4-sp-d16 -Os -std=c99
  -Wall -Wextra -Werror -pedantic -ffreestanding -nostdlib -ffunction-sections -fdata-sections)
link() {
  arm-none-eabi-gcc "${flags[@]}" -Iinclude -T embedded/c-link/link.ld \
    -Wl,--gc-sections -Wl,-z,noexecstack embedded/c-link/main.c "$1" -lgcc -o "$2"
  python3 scripts/elf_size.py "$2"
}
link "$lib" "$elf"
run_on_boards "the C program hovers with tvmd" "$elf" "the C program failed"

# The flash build of docs/c-interface.md, Footprint (opt-level z, LLVM inline threshold 40;
# scripts/ffi.sh checks its size and that it has no panic path): the same program must fly on it.
# Its own target directory, so that neither build invalidates the other's cache.
CARGO_PROFILE_RELEASE_OPT_LEVEL=z CARGO_ENCODED_RUSTFLAGS="-Cllvm-args=-inline-threshold=40" \
  cargo build --locked -p tvmd-ffi --no-default-features --target thumbv7em-none-eabihf --release \
  --target-dir "$target_dir/flash"
flash_elf="$target_dir/c-link/tvmd-c-link-flash.elf"
link "$target_dir/flash/thumbv7em-none-eabihf/release/libtvmd_ffi.a" "$flash_elf"
run_on_boards "the C program hovers with tvmd built for flash" "$flash_elf" \
  "the C program failed on the flash build"

#!/usr/bin/env bash
# The processor-in-the-loop firmware: embedded/target-tests, bin tvmd-pil (the f32 core served
# over the mps2 boards' UART0), which `tvmd-sim run SCENARIO --pil cortex-m4|cortex-m7` runs in
# QEMU (qemu-system-arm; `bash scripts/target.sh` installs it).
#   bash scripts/pil.sh build   builds it and prints the ELF's path (tvmd-sim finds it there,
#                               or wherever TVMD_PIL_FIRMWARE points)
set -euo pipefail
cd "$(dirname "$0")/.."

case "${1:-}" in
  build)
    rustup target add thumbv7em-none-eabihf >/dev/null
    cargo build --release --locked --manifest-path embedded/target-tests/Cargo.toml \
      --target thumbv7em-none-eabihf --bin tvmd-pil
    target_dir=${CARGO_TARGET_DIR:-embedded/target-tests/target}
    realpath "$target_dir/thumbv7em-none-eabihf/release/tvmd-pil"
    ;;
  *)
    echo "usage: bash scripts/pil.sh build" >&2
    exit 2
    ;;
esac

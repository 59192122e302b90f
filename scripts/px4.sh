#!/usr/bin/env bash
# PX4 in the loop (docs/px4.md): builds PX4 SITL in the PX4 tree PX4_DIR and flies it on
# tvmd-sim in lockstep, asserting what each flight must show.
#
#   PX4_DIR=/path/to/PX4-Autopilot bash scripts/px4.sh
#
# Installs what PX4's build needs where it is missing (Debian packages with apt-get; a Python
# venv in target/px4-venv with empy 3.3.4 and PX4's generators, and pyulog for the checks), builds
# `make px4_sitl_default` in PX4_DIR (incremental after the first time), builds tvmd-sim (ci
# profile), then flies:
#   1. PX4's stock quadcopter (airframe 10016, its multicopter controllers) on tvmd's A4-Con team
#      with gimbals at zero: takeoff, hover at 1.5 m, 1 m step north, land; checked from the
#      ulog (armed, airborne, no failsafe or estimator failure, hover within 0.1 m, the
#      estimate within 0.1 m and 0.02 rad of the truth through the hover, the step settled, landed);
#   2. the same script on PX4's own SIH quadcopter (real time), for comparison, checked the same
#      way except for the hover target.
# TVMD_PX4_INSTANCE=N runs PX4 as instance N (ports 4560 + N, 18570 + N; default 0). The flights'
# logs, ulogs and reports go to target/px4-flights/.
set -euo pipefail
cd "$(dirname "$0")/.."

step() { printf '\n==> %s\n' "$*"; }

if [ -z "${PX4_DIR:-}" ]; then
  echo "error: set PX4_DIR to a PX4 source tree (e.g. a clone of PX4-Autopilot with its submodules)" >&2
  exit 1
fi
if [ ! -f "$PX4_DIR/ROMFS/px4fmu_common/init.d-posix/rcS" ]; then
  echo "error: PX4_DIR=$PX4_DIR is not a PX4 source tree (no ROMFS/px4fmu_common/init.d-posix/rcS)" >&2
  exit 1
fi
PX4_DIR=$(cd "$PX4_DIR" && pwd)
instance=${TVMD_PX4_INSTANCE:-0}
out=target/px4-flights
mkdir -p "$out"

step "PX4's build needs: Debian packages and a Python venv (target/px4-venv)"
missing=()
for tool in cmake ninja g++ make git; do
  command -v "$tool" >/dev/null 2>&1 || missing+=("$tool")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "installing: ${missing[*]}"
  sudo_=""; [ "$(id -u)" -ne 0 ] && sudo_="sudo"
  $sudo_ apt-get update -qq
  $sudo_ apt-get install -y -qq cmake ninja-build g++ make git python3-venv
fi
python3 -m venv target/px4-venv
# PX4's generators need empy 3 (PX4 fails with empy 4); pyulog reads the flights' ulogs.
target/px4-venv/bin/python -m pip install --quiet --disable-pip-version-check \
  empy==3.3.4 pyros-genmsg kconfiglib jinja2 pyyaml jsonschema lxml future packaging toml psutil \
  numpy pyulog==1.2.2

step "PX4 SITL: make px4_sitl_default in $PX4_DIR"
start=$SECONDS
# GIT_SUBMODULES_ARE_EVIL: PX4's build must not fetch submodules (the tree brings its own).
(
  export PATH="$PWD/target/px4-venv/bin:$PATH"
  cd "$PX4_DIR" && GIT_SUBMODULES_ARE_EVIL=1 make px4_sitl_default
)
echo "PX4 build: $((SECONDS - start)) s"

step "tvmd-sim (ci profile)"
cargo build --profile ci -p tvmd-cli
sim=target/ci/tvmd-sim
py=target/px4-venv/bin/python

step "flight 1: PX4's stock quadcopter on tvmd-sim (lockstep)"
start=$SECONDS
"$sim" px4 scripts/px4/quad/scenario.toml --flight scripts/px4/quad/flight.toml \
  --px4-dir "$PX4_DIR" --autostart 10016 --params scripts/px4/quad/params \
  --instance "$instance" --out "$out/quad.mcap"
echo "flight 1: $((SECONDS - start)) s wall"
"$py" scripts/px4/analyze.py "$out/quad.ulg" --hover 25 30 --step 30 45 --expect-flight \
  --json "$out/quad.analysis.json" >/dev/null
"$py" scripts/px4/check.py "$out/quad.analysis.json" "$out/quad.px4.json" \
  --hover-hold 0.1 --ekf-position 0.1 --ekf-attitude 0.02 --settle 10

step "flight 2: PX4's stock quadcopter on PX4's SIH (real time, comparison)"
start=$SECONDS
"$sim" px4 scripts/px4/quad/scenario.toml --flight scripts/px4/quad/flight.toml \
  --px4-dir "$PX4_DIR" --sih --params scripts/px4/quad/sih.params \
  --instance "$instance" --out "$out/quad-sih.mcap"
echo "flight 2: $((SECONDS - start)) s wall"
"$py" scripts/px4/analyze.py "$out/quad-sih.ulg" --hover 25 30 --step 30 45 --expect-flight \
  --json "$out/quad-sih.analysis.json" >/dev/null
"$py" scripts/px4/check.py "$out/quad.analysis.json" "$out/quad-sih.analysis.json" --compare

step "PX4 flights passed"

#!/usr/bin/env bash
# Builds a PX4 tree (v1.15 or later) with tvmd's PX4 module tvmd_control (px4/, a PX4
# external-modules folder); with --smoke, checks that the module starts in SITL, refuses a bad
# parameter and keeps running; with --fly, flies it on tvmd-sim in lockstep (tvmd-sim px4) and
# checks the flights from their ulogs (docs/px4-module.md).
#
#   bash scripts/px4-module.sh PX4_DIR [--smoke] [--fly] [--teams] [--side-by-side] [--perf]   (or PX4_DIR=... bash scripts/px4-module.sh)
#
# What it changes in PX4_DIR (each once; rerunning is safe):
#   - installs the airframes px4/airframes/4090-4095_tvmd_control_* (+ .post, and the files
#     they source, rc.tvmd_control_defaults and rc.tvmd_control_apps) into
#     ROMFS/px4fmu_common/init.d-posix/airframes and lists them in that folder's CMakeLists.txt;
#   - adds tvmd_control_status to the logger's default topics (src/modules/logger/
#     logged_topics.cpp), so that every ulog has it.
# Then it runs `make $PX4_TARGET EXTERNAL_MODULES_LOCATION=<repo>/px4` (PX4_TARGET defaults to
# px4_sitl_default; GIT_SUBMODULES_ARE_EVIL defaults to 1, so PX4 does not update submodules
# over the network). PX4's Python build dependencies must be importable: activate their
# virtual environment first, or name it in PX4_VENV. The build log goes to
# PX4_DIR/build/tvmd-module-build-<target>.log.
#
# --fly builds tvmd-sim (cargo, release; or TVMD_SIM names a tvmd-sim binary) and flies
# scripts/px4/tvmd_control/flight.toml twice, on the nominal team and with model error (+3% mass,
# gimbal offsets): takeoff, hover with a bad parameter refused in flight, the paper's tilt through
# the sticks, landing; scripts/px4/tvmd_control.py checks each (hover rms error at most 2 cm, the
# tilt held within 0.1 m, the largest planned roll within 0.02 rad of tvmd-sim's own flight of the
# reference, the parameter refused, no refused period, no non-finite output, landed). Then an
# agent failure, told (scenario-agent-failure.toml): the hover certificate lost, tvmd_control
# asks PX4 to land (land mode within 1 s), the team lands on three agents (tilt at most 0.8 rad,
# standing within 0.15 m of the target, disarmed). It needs
# pyulog in the Python environment. Logs, ulogs and measures go to target/px4-module-flights/;
# PX4_INSTANCE (default 7) keeps its ports apart from other SITL runs. --side-by-side flies
# tvmd_control and the authors' modules (their PX4 fork) on the nominal vehicle, under a steady
# wind and off its model (the hover, and the tilt: theirs in their manual mode, the throttle
# trimmed for the model error), then an agent failure in each one's hover, and prints the tables
# of docs/px4-side-by-side.md (scripts/px4/side_by_side.py; not asserted, 11 flights, about 3.5
# minutes). --perf (not in the test command: a second PX4 build, then about 8 minutes of
# flights) builds px4_sitl_nolockstep too (PX4's SITL without lockstep: its clock, and so its
# perf counters, on the wall clock) and flies both stacks' hover and tilt on tvmd-sim in real
# time (`tvmd-sim px4 --real-time`; each stack's again under the wind and the model error),
# reading PX4's perf counters in each window (scripts/px4/perf.py): each stack's time per cycle
# (PX4_TARGET=px4_sitl_nolockstep builds that one alone); the side-by-side table then shows it.
# --teams (not in the test command: ten flights, about two minutes on a built tree) flies
# flight.toml with the catalogue's other teams of at most four agents, each on its own airframe
# (4091 a3-con, 4092 a3-inc, 4093 a4-con, 4094 a4-diamond-con, 4095 a4-diamond-inc; tvmd-sim's
# team the same preset), nominal and with --fly's model error, and checks each as --fly does,
# against tvmd-sim's own flight of the reference with the same team (docs/px4-teams.md).
set -euo pipefail
repo="$(cd "$(dirname "$0")/.." && pwd)"

px4_dir="${PX4_DIR:-}"
smoke=0
fly=0
side=0
perf=0
teams=0
for arg in "$@"; do
  case "$arg" in
    --smoke) smoke=1 ;;
    --fly) fly=1 ;;
    --side-by-side) side=1 ;;
    --perf) perf=1 ;;
    --teams) teams=1 ;;
    -h|--help) sed -n '2,48p' "$0"; exit 0 ;;
    *) px4_dir="$arg" ;;
  esac
done
if [ -z "$px4_dir" ]; then
  echo "error: no PX4 tree: give its path (bash scripts/px4-module.sh PX4_DIR) or set PX4_DIR" >&2
  exit 2
fi
if [ ! -f "$px4_dir/Makefile" ] || [ ! -d "$px4_dir/src/modules/logger" ] || [ ! -d "$px4_dir/msg" ]; then
  echo "error: $px4_dir is not a PX4 source tree (no Makefile, src/modules/logger or msg/)" >&2
  exit 2
fi
px4_dir="$(cd "$px4_dir" && pwd)"
target="${PX4_TARGET:-px4_sitl_default}"
step() { printf '\n==> %s\n' "$*"; }

if [ -n "${PX4_VENV:-}" ]; then
  # shellcheck disable=SC1091
  source "$PX4_VENV/bin/activate"
fi
python3 -c 'import em, genmsg, kconfiglib, jinja2, yaml' 2>/dev/null || {
  echo "error: PX4's Python build dependencies are missing (empy==3.3.4 pyros-genmsg kconfiglib jinja2 pyyaml jsonschema ...): activate their venv or set PX4_VENV" >&2
  exit 2
}

step "airframes 4090-4095_tvmd_control_* into $px4_dir"
airframes="$px4_dir/ROMFS/px4fmu_common/init.d-posix/airframes"
# PX4 (v1.15) takes ROMFS files only from its own tree: an external-modules folder cannot add
# an airframe, so they are copied there, with the two files they share.
for f in $(cd "$repo/px4/airframes" && ls); do
  cp "$repo/px4/airframes/$f" "$airframes/$f"
  if ! grep -qE "^[[:space:]]*$f\$" "$airframes/CMakeLists.txt"; then
    sed -i "s/^px4_add_romfs_files(\$/px4_add_romfs_files(\n\t$f/" "$airframes/CMakeLists.txt"
  fi
  grep -qE "^[[:space:]]*$f\$" "$airframes/CMakeLists.txt" || {
    echo "error: could not list $f in $airframes/CMakeLists.txt" >&2
    exit 1
  }
done

step "tvmd_control_status in the logger's default topics"
topics="$px4_dir/src/modules/logger/logged_topics.cpp"
if ! grep -q '"tvmd_control_status"' "$topics"; then
  sed -i 's/^void LoggedTopics::add_default_topics()$/&\n{\n\tadd_optional_topic("tvmd_control_status", 10);\n\tadd_optional_topic("tvmd_pose_setpoint");/' "$topics"
  # The function's own brace follows: drop it (the inserted block opened the body).
  python3 - "$topics" <<'EOF'
import sys
path = sys.argv[1]
text = open(path).read()
marker = 'add_optional_topic("tvmd_pose_setpoint");\n{\n'
assert marker in text, "logged_topics.cpp: unexpected layout after add_default_topics()"
open(path, "w").write(text.replace(marker, 'add_optional_topic("tvmd_pose_setpoint");\n', 1))
EOF
fi
grep -q '"tvmd_control_status"' "$topics"

build_px4() {
  step "make $1 EXTERNAL_MODULES_LOCATION=$repo/px4"
  local log="$px4_dir/build/tvmd-module-build-$1.log" start
  mkdir -p "$px4_dir/build"
  start=$(date +%s)
  if ! (cd "$px4_dir" && GIT_SUBMODULES_ARE_EVIL="${GIT_SUBMODULES_ARE_EVIL:-1}" \
    make "$1" EXTERNAL_MODULES_LOCATION="$repo/px4" >"$log" 2>&1); then
    tail -40 "$log"
    echo "error: the PX4 build failed; its log: $log" >&2
    exit 1
  fi
  echo "built in $(($(date +%s) - start)) s (log: $log)"
}
build_px4 "$target"

[ "$smoke" -eq 1 ] || [ "$fly" -eq 1 ] || [ "$side" -eq 1 ] || [ "$perf" -eq 1 ] || [ "$teams" -eq 1 ] || exit 0
case "$target" in
  px4_sitl*) ;;
  *) echo "error: --smoke, --fly, --teams, --side-by-side and --perf need a SITL target (PX4_TARGET=$target)" >&2; exit 2 ;;
esac
build="$px4_dir/build/$target"
instance="${PX4_INSTANCE:-7}"

if [ "$fly" -eq 1 ] || [ "$side" -eq 1 ] || [ "$perf" -eq 1 ] || [ "$teams" -eq 1 ]; then
  python3 -c 'import pyulog' 2>/dev/null || {
    echo "error: --fly reads the ulogs with pyulog: install it in the Python environment (pip install pyulog)" >&2
    exit 2
  }
  sim="${TVMD_SIM:-}"
  if [ -z "$sim" ]; then
    step "tvmd-sim (cargo build --release -p tvmd-cli)"
    (cd "$repo" && cargo build --release --locked -p tvmd-cli)
    sim="$repo/target/release/tvmd-sim"
  fi
  out="$repo/target/px4-module-flights"
  mkdir -p "$out"
  flights="$repo/scripts/px4/tvmd_control"
fi

if [ "$perf" -eq 1 ]; then
  # Not in the test command: PX4's perf counters read hrt, which in lockstep SITL is the
  # simulated clock (0 us a cycle). A build without lockstep runs on the wall clock; tvmd-sim
  # paces it in real time.
  perf_target=px4_sitl_nolockstep
  [ "$target" = "$perf_target" ] || build_px4 "$perf_target"
  step "perf: each stack's time per cycle on real time ($perf_target, tvmd-sim px4 --real-time)"
  python3 "$repo/scripts/px4/perf.py" --sim "$sim" --px4-dir "$px4_dir" --build "$perf_target" \
    --instance "$instance" --out "$out/perf"
fi

if [ "$side" -eq 1 ]; then
  # Not in the test command (about three minutes): each stack on the nominal vehicle, under a
  # steady wind and off its model: tvmd_control's flight (hover and tilt), the authors' hover in
  # their position mode and their tilt in their manual mode (under the model error with the
  # throttle trimmed, flight-trimmed.toml); then agent 0 lost in each stack's hover (told to
  # tvmd_control, untold to theirs: their stack has no way to be told). The tables of
  # docs/px4-side-by-side.md. The authors' modules need their PX4 fork (airframe 4007).
  authors="$repo/scripts/px4/authors"
  fly_side() { # stack-and-flight name, airframe, scenario, flight file
    local params="$flights/params"
    [ "$2" = 4090 ] || params="$authors/params"
    step "side by side: $1 (airframe $2)"
    "$sim" px4 "$3" --flight "$4" --px4-dir "$px4_dir" --px4-build "$target" --autostart "$2" \
      --params "$params" --instance "$instance" --out "$out/$1.mcap" >/dev/null
  }
  for flight in nominal wind model-error; do
    scenario=scenario; [ "$flight" = nominal ] || scenario="scenario-$flight"
    manual=flight; [ "$flight" = model-error ] && manual=flight-trimmed
    fly_side "tvmd-$flight" 4090 "$flights/$scenario.toml" "$flights/flight.toml"
    fly_side "authors-$flight" 4007 "$authors/$scenario.toml" "$authors/flight-hold.toml"
    fly_side "authors-tilt-$flight" 4007 "$authors/$scenario.toml" "$authors/$manual.toml"
  done
  fly_side tvmd-agent-failure 4090 "$flights/scenario-agent-failure.toml" "$flights/flight-agent-failure.toml"
  fly_side authors-agent-failure 4007 "$authors/scenario-agent-failure.toml" "$authors/flight-agent-failure.toml"
  python3 "$repo/scripts/px4/side_by_side.py" "$out"
fi

if [ "$fly" -eq 1 ]; then
  step "tvmd-sim's own flight of the reference (the paper's tilt, tvmd_control's law)"
  "$sim" run "$flights/own-tilt.toml" --summary "$out/own-tilt.json" --out "$out/own-tilt.mcap" >/dev/null
  for flight in scenario scenario-model-error; do
    step "tvmd_control in PX4 on tvmd-sim: $flight"
    start=$(date +%s)
    "$sim" px4 "$flights/$flight.toml" --flight "$flights/flight.toml" --px4-dir "$px4_dir" \
      --px4-build "$target" --autostart 4090 --params "$flights/params" --instance "$instance" \
      --out "$out/$flight.mcap"
    echo "flown in $(($(date +%s) - start)) s wall"
    python3 "$repo/scripts/px4/tvmd_control.py" "$out/$flight.ulg" "$out/$flight.px4.json" \
      --own "$out/own-tilt.json" --refused-at 30 --hover-rms 0.02 --tilt-hold 0.1 \
      --json "$out/$flight.measures.json"
  done
  step "tvmd_control in PX4 on tvmd-sim: an agent failure, told (the certificate lost: PX4 lands it)"
  start=$(date +%s)
  "$sim" px4 "$flights/scenario-agent-failure.toml" --flight "$flights/flight-agent-failure.toml" \
    --px4-dir "$px4_dir" --px4-build "$target" --autostart 4090 --params "$flights/params" \
    --instance "$instance" --out "$out/agent-failure.mcap"
  echo "flown in $(($(date +%s) - start)) s wall"
  python3 "$repo/scripts/px4/tvmd_control.py" "$out/agent-failure.ulg" "$out/agent-failure.px4.json" \
    --failed-tilt 0.8 --failed-landing 0.15 --json "$out/agent-failure.measures.json"
  echo "tvmd_control flew hover, the tilt and the agent failure in PX4 SITL (ulogs in $out)"
fi

if [ "$teams" -eq 1 ]; then
  # The catalogue's other teams of at most four agents, each on its airframe; tvmd-sim flies the
  # same preset (scenario.toml with its team replaced) and its own flight of the reference with
  # it (own-tilt.toml --team). The flight's parameters are params without the A4-Inc geometry
  # (the airframe carries the team's).
  teams_out="$out/teams"
  mkdir -p "$teams_out"
  grep -v '^param set TVMD_AG' "$flights/params" >"$teams_out/params"
  for entry in 4091:a3-con 4092:a3-inc 4093:a4-con 4094:a4-diamond-con 4095:a4-diamond-inc; do
    autostart="${entry%%:*}" preset="${entry#*:}"
    step "tvmd-sim's own flight of the reference with $preset"
    "$sim" run "$flights/own-tilt.toml" --team "$preset" --summary "$teams_out/own-tilt-$preset.json" \
      --out "$teams_out/own-tilt-$preset.mcap" >/dev/null
    for flight in scenario scenario-model-error; do
      # The model error's gimbal offsets name four agents: a three-agent team drops the last
      # (agent 3's, zero).
      name="$preset"; [ "$flight" = scenario ] || name="$preset-model-error"
      sed 's/^preset = "a4-inc"$/preset = "'"$preset"'"/' "$flights/$flight.toml" >"$teams_out/$name.toml"
      case "$preset" in
        a3-*) sed -i 's/^\(gimbal_offsets = .*\), \[0\.0, 0\.0\]\]$/\1]/' "$teams_out/$name.toml" ;;
      esac
      grep -q "^preset = \"$preset\"$" "$teams_out/$name.toml"
      step "tvmd_control in PX4 on tvmd-sim: $name (airframe $autostart)"
      start=$(date +%s)
      "$sim" px4 "$teams_out/$name.toml" --flight "$flights/flight.toml" --px4-dir "$px4_dir" \
        --px4-build "$target" --autostart "$autostart" --params "$teams_out/params" --instance "$instance" \
        --out "$teams_out/$name.mcap"
      echo "flown in $(($(date +%s) - start)) s wall"
      python3 "$repo/scripts/px4/tvmd_control.py" "$teams_out/$name.ulg" "$teams_out/$name.px4.json" \
        --own "$teams_out/own-tilt-$preset.json" --refused-at 30 --hover-rms 0.02 --tilt-hold 0.1 \
        --json "$teams_out/$name.measures.json"
    done
  done
  echo "tvmd_control flew hover and the tilt with every catalogue team of at most four agents (ulogs in $teams_out)"
fi

[ "$smoke" -eq 1 ] || exit 0
step "smoke: PX4 SITL (SIH quadcopter for sensors), tvmd_control started, a bad parameter refused"
work="$(mktemp -d)"
px4_pid=""
cleanup() {
  if [ -n "$px4_pid" ]; then kill "$px4_pid" 2>/dev/null || true; wait "$px4_pid" 2>/dev/null || true; fi
  rm -rf "$work"
}
trap cleanup EXIT
# The SIH quadcopter's own controllers stay on the ground (disarmed); tvmd_control runs beside
# them on the estimator's state and publishes its outputs, which nothing arms.
PX4_SYS_AUTOSTART=10040 PX4_SIM_MODEL=sihsim_quadx PX4_SIMULATOR=sihsim \
  "$build/bin/px4" -d -i "$instance" -w "$work/rootfs" "$build/etc" >"$work/px4.log" 2>&1 &
px4_pid=$!
# Its own PX4 instance (daemon socket, MAVLink ports), so that it runs beside other SITL runs.
client() { (cd "$work/rootfs" && timeout 20 "$build/bin/px4-$1" --instance "$instance" "${@:2}"); }
for _ in $(seq 1 60); do
  grep -q "Ready for takeoff\|Startup script returned successfully" "$work/px4.log" 2>/dev/null && break
  kill -0 "$px4_pid" 2>/dev/null || { cat "$work/px4.log"; echo "error: PX4 exited" >&2; exit 1; }
  sleep 1
done
client tvmd_control start
sleep 3
client tvmd_control status | tee "$work/status1.txt"
client param set TVMD_S 1.5
sleep 3
client tvmd_control status | tee "$work/status2.txt"
client param set TVMD_S 0.6
sleep 3
client tvmd_control status | tee "$work/status3.txt"
client perf | grep tvmd_control | tee "$work/perf.txt" || true
client tvmd_control stop
fail=0
grep -q "parameters (tvmd_reconfigure): last TVMD_ERR_CONFIG_RELAXATION, 1 refused" "$work/status2.txt" ||
  { echo "error: TVMD_S 1.5 was not refused with TVMD_ERR_CONFIG_RELAXATION" >&2; fail=1; }
grep -q "parameters (tvmd_reconfigure): last TVMD_OK, 1 refused" "$work/status3.txt" ||
  { echo "error: TVMD_S 0.6 was not accepted after the refusal" >&2; fail=1; }
# Still running the whole time: the rate loop's event count grew between the checks.
events() { grep -m1 "attitude+allocation" "$1" | sed -E 's/.*: ([0-9]+) events.*/\1/'; }
e1=$(events "$work/status1.txt"); e3=$(events "$work/status3.txt")
echo "rate-loop periods: $e1 after start, $e3 after the refusal and the accepted change"
if [ -z "$e1" ] || [ -z "$e3" ] || [ "$e3" -le "$e1" ]; then
  echo "error: the rate loop did not keep running" >&2; fail=1
fi
if [ "$fail" -ne 0 ]; then
  tail -40 "$work/px4.log"
  exit 1
fi
echo "tvmd_control started in SITL, refused TVMD_S = 1.5 and kept running, accepted 0.6"

# Sourced by the scripts that run firmware on QEMU's Arm boards.

# run_on_boards WHAT ELF FAILURE [QEMU FLAG...]: runs the semihosting firmware ELF on QEMU's
# Cortex-M4F (mps2-an386) and Cortex-M7 (mps2-an500) boards, the second even when the first
# fails; returns 1 when either exits with failure (FAILURE says what that means) or hangs. The
# firmware exits through semihosting in seconds (faults and panics exit with failure); the
# 120 s timeout only catches a hang.
run_on_boards() {
  local what=$1 elf=$2 failure=$3 machine rc result=0
  shift 3
  for machine in mps2-an386 mps2-an500; do
    echo "==> $machine: $what"
    rc=0
    timeout 120 qemu-system-arm -machine "$machine" -nographic -monitor none "$@" \
      -semihosting-config enable=on,target=native -kernel "$elf" || rc=$?
    if [ "$rc" -eq 124 ]; then
      echo "error: $machine: $what timed out (the firmware hung)" >&2
      result=1
    elif [ "$rc" -ne 0 ]; then
      echo "error: $machine: $failure (exit status $rc)" >&2
      result=1
    fi
  done
  return "$result"
}

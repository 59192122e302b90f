# Sourced by the test scripts: `require COMMAND PACKAGE...` installs the Debian packages with
# apt-get (as root, or through sudo; without recommends) when COMMAND is not on PATH, and fails
# with a message naming them when it cannot.
require() {
  local command=$1
  shift
  command -v "$command" >/dev/null 2>&1 && return 0
  echo "==> $command not found: installing $* with apt-get"
  local as_root=()
  if [ "$(id -u)" -ne 0 ]; then
    if command -v sudo >/dev/null 2>&1; then
      as_root=(sudo)
    else
      echo "error: $command is missing and this user can neither install packages (not root) nor use sudo; install $* and rerun" >&2
      return 1
    fi
  fi
  if ! { "${as_root[@]}" apt-get update -q &&
    "${as_root[@]}" env DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends "$@"; }; then
    echo "error: apt-get could not install $*; install it by hand and rerun" >&2
    return 1
  fi
  command -v "$command" >/dev/null 2>&1 || {
    echo "error: $command still not on PATH after apt-get install $*" >&2
    return 1
  }
}

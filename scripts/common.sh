# Shared by scripts/demo and scripts/test: Debian packages and the CMake build.
# shellcheck shell=bash

TICKFX_ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
TICKFX_BUILD=${TICKFX_BUILD:-$TICKFX_ROOT/build}

# Everything tickfx builds with, from Debian's archive only.
TICKFX_PACKAGES=(
  cmake ninja-build g++ clang pkg-config
  libeigen3-dev libtbb-dev libtomlplusplus-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  libopenvdb-dev libopenvdb-tools libboost-dev libboost-iostreams-dev zlib1g-dev
  python3-dev pybind11-dev python3-numpy python3-pytest
)

# Installs the packages that are missing. As root it runs apt-get itself (with one update first,
# since a fresh machine has no package lists); otherwise it prints the one command to run.
ensure_packages() {
  local missing=() p
  for p in "${TICKFX_PACKAGES[@]}"; do
    if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
      missing+=("$p")
    fi
  done
  [ ${#missing[@]} -eq 0 ] && return 0
  echo "tickfx: installing Debian packages: ${missing[*]}"
  if [ "$(id -u)" -ne 0 ]; then
    echo "tickfx: not root; run this, then try again:" >&2
    echo "  sudo apt-get update && sudo apt-get install -y ${missing[*]}" >&2
    exit 1
  fi
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq
  apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
}

# configure BUILD_DIR [cmake args...]: configures (Release unless told).
configure() {
  local dir=$1
  shift
  cmake -S "$TICKFX_ROOT" -B "$dir" -G Ninja -DCMAKE_BUILD_TYPE=Release "$@"
}

# configure_and_build BUILD_DIR [cmake args...]: configures and builds everything on every core.
configure_and_build() {
  configure "$@"
  cmake --build "$1" -j "$(nproc)"
}

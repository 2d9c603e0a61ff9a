# Shared by scripts/demo and scripts/test: Debian packages and the CMake build.
# shellcheck shell=bash

TICKFX_ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
TICKFX_BUILD=${TICKFX_BUILD:-$TICKFX_ROOT/build}

# Everything tickfx builds with, from Debian's archive only.
TICKFX_PACKAGES=(
  cmake ninja-build g++ clang clang-format lld pkg-config
  libeigen3-dev libtbb-dev libtomlplusplus-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  libopenvdb-dev libopenvdb-tools libboost-dev libboost-iostreams-dev zlib1g-dev
  python3-dev pybind11-dev python3-numpy python3-pytest python3-matplotlib libpng-dev libgif-dev
)

# What scripts/test adds for the tests: Debian's Blender (3.4.1, headless with -b) for the
# add-on's, which runs Debian's python3 and so imports the tickfx module; Dask's distributed
# (python3-distributed, 2022.12) for tickfx.distributed's, on a local cluster. scripts/demo does
# without them.
# shellcheck disable=SC2034 # scripts/test installs them with the rest
TICKFX_TEST_PACKAGES=(blender python3-distributed)

# What scripts/test's aarch64 stage adds: Debian's cross compiler, qemu-user, and the arm64 builds
# of the libraries (Multi-Arch: same, installed beside the amd64 ones). OpenVDB comes as its
# runtime package only: its -dev package is not Multi-Arch (cmake/toolchains/aarch64-linux-gnu.cmake
# says how the cross build does without it).
# shellcheck disable=SC2034 # scripts/test installs them with the rest
TICKFX_AARCH64_PACKAGES=(
  g++-aarch64-linux-gnu qemu-user
  libtbb-dev:arm64 libtomlplusplus-dev:arm64 libblosc-dev:arm64 libimath-dev:arm64
  libboost-iostreams-dev:arm64 zlib1g-dev:arm64 libopenvdb10.0:arm64 libpng-dev:arm64
  libgif-dev:arm64
)

# The architectures named by PKG:ARCH arguments that dpkg does not know yet, one a line.
new_architectures() {
  local known p
  known=" $(dpkg --print-architecture) $(dpkg --print-foreign-architectures | tr '\n' ' ') "
  for p in "$@"; do
    if [[ $p == *:* && $known != *" ${p##*:} "* ]]; then
      echo "${p##*:}"
    fi
  done | sort -u
}

# ensure_packages [PACKAGE...]: installs those of the packages (default TICKFX_PACKAGES) that are
# missing. As root it runs apt-get itself, first adding the foreign architectures that PKG:ARCH
# names need and updating the package lists (a fresh machine has none, nor those of an
# architecture it has just been given); otherwise it prints the commands to run.
ensure_packages() {
  local wanted=("$@") missing=() p arch archs
  [ $# -eq 0 ] && wanted=("${TICKFX_PACKAGES[@]}")
  for p in "${wanted[@]}"; do
    if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
      missing+=("$p")
    fi
  done
  [ ${#missing[@]} -eq 0 ] && return 0
  archs=$(new_architectures "${missing[@]}")
  echo "tickfx: installing Debian packages: ${missing[*]}"
  if [ "$(id -u)" -ne 0 ]; then
    echo "tickfx: not root; run this, then try again:" >&2
    for arch in $archs; do
      echo "  sudo dpkg --add-architecture $arch" >&2
    done
    echo "  sudo apt-get update && sudo apt-get install -y ${missing[*]}" >&2
    exit 1
  fi
  for arch in $archs; do
    dpkg --add-architecture "$arch"
  done
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq
  apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
}

# configure BUILD_DIR [cmake args...]: configures (Release unless told), as a unity build: each
# library compiles as a few large translation units, so the headers (Eigen, OpenVDB, the standard
# library) are parsed a few times instead of once a file. scripts/test's Release build took 397 s
# file by file on 2 cores. A plain `cmake -B build` still compiles file by file: developers build
# that way, which is what keeps every file's includes its own.
#
# Linked by LLVM's lld where the compiler can use it (TICKFX_LLD: Debian's lld, for g++ and
# clang++ alike): it links a sanitised test in a quarter of GNU ld's time (0.75 s against 2.95 s),
# about a minute of scripts/test's builds on 2 cores. A linker does no arithmetic, so no bit
# changes.
configure() {
  local dir=$1
  shift
  cmake -S "$TICKFX_ROOT" -B "$dir" -G Ninja -DCMAKE_BUILD_TYPE=Release -DCMAKE_UNITY_BUILD=ON \
    -DTICKFX_LLD=ON "$@"
}

# configure_and_build BUILD_DIR [cmake args...]: configures and builds everything on every core.
configure_and_build() {
  configure "$@"
  cmake --build "$1" -j "$(nproc)"
}

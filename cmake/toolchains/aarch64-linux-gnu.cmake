# Cross-compiles tickfx for 64-bit Arm Linux on a Debian amd64 machine: Debian's cross compiler
# (g++-aarch64-linux-gnu) against the multiarch :arm64 libraries in /usr/lib/aarch64-linux-gnu.
# scripts/test installs both (TICKFX_AARCH64_PACKAGES in scripts/common.sh) and runs the result
# under qemu-user:
#   cmake -S . -B build/aarch64 -G Ninja --toolchain cmake/toolchains/aarch64-linux-gnu.cmake \
#     -DTICKFX_BUILD_TESTS=OFF -DTICKFX_BUILD_BENCH=OFF -DTICKFX_BUILD_SAMPLES=OFF \
#     -DTICKFX_BUILD_PYTHON=OFF
set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_SYSTEM_PROCESSOR aarch64)
set(CMAKE_C_COMPILER aarch64-linux-gnu-gcc)
set(CMAKE_CXX_COMPILER aarch64-linux-gnu-g++)
# No -L prefix: libc6:arm64 (a dependency of the :arm64 libraries) puts the arm64 loader where the
# binary names it, so the loader and libc come from one package, as on an Arm machine.
set(CMAKE_CROSSCOMPILING_EMULATOR qemu-aarch64)

# Debian's libopenvdb-dev is not Multi-Arch: installing its :arm64 build removes the amd64 one
# that the native build needs. What it adds on top of libopenvdb10.0:arm64 is the same file for
# file on both architectures (headers and find modules, compared for 10.0.1-2) except the
# unversioned link to the library. So the headers and FindOpenVDB.cmake come from the host's
# package, and the library is named by its file: the SONAME behind the package name
# libopenvdb10.0. Every other library has its :arm64 -dev package (Multi-Arch: same).
set(TICKFX_OPENVDB_MODULE_DIR /usr/lib/${CMAKE_HOST_SYSTEM_PROCESSOR}-linux-gnu/cmake/OpenVDB
    CACHE PATH "Where FindOpenVDB.cmake is (the host's libopenvdb-dev)")
set(OpenVDB_openvdb_LIBRARY /usr/lib/aarch64-linux-gnu/libopenvdb.so.10.0
    CACHE FILEPATH "The arm64 OpenVDB library (libopenvdb10.0:arm64)")
foreach(file ${TICKFX_OPENVDB_MODULE_DIR}/FindOpenVDB.cmake ${OpenVDB_openvdb_LIBRARY})
  if(NOT EXISTS ${file})
    message(FATAL_ERROR "aarch64 toolchain: ${file} is missing. scripts/test installs what the "
                        "cross build needs (TICKFX_AARCH64_PACKAGES in scripts/common.sh).")
  endif()
endforeach()

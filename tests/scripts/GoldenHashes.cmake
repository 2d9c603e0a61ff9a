# cmake -P script: runs every sample of GOLDEN_FILE and every golden effect of GOLDEN_EFFECTS_FILE
# through one `tickfx` binary, TICKFX, and fails with a table unless every state hash is the
# golden one. scripts/test runs it on its cross-built aarch64 binary under qemu-user, where ctest
# cannot run the test suite itself.
#
# Inputs: SOURCE_DIR, TICKFX, NAME (a label for the binary), GOLDEN_FILE, GOLDEN_EFFECTS_FILE (as
# for BuildVariants.cmake), and optionally LAUNCHER (a ;-list the binary runs under, such as
# qemu-aarch64).
cmake_minimum_required(VERSION 3.22)

foreach(var SOURCE_DIR TICKFX NAME GOLDEN_FILE GOLDEN_EFFECTS_FILE)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "GoldenHashes.cmake: -D${var}=... is required")
  endif()
endforeach()
include(${CMAKE_CURRENT_LIST_DIR}/GoldenRuns.cmake)

set(${NAME}_tickfx ${TICKFX})
set(${NAME}_launcher ${LAUNCHER})
set(failures 0)
golden_check(failures ${NAME})
if(failures GREATER 0)
  message(FATAL_ERROR "${NAME}: ${failures} run(s) did not give the golden hash of ${GOLDEN_FILE} "
                      "or ${GOLDEN_EFFECTS_FILE}. The promise is that the state after tick k is "
                      "the same bits on every architecture that tickfx is built for.")
endif()
message("${NAME}: every golden hash")

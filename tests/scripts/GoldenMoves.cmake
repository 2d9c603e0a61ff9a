# cmake -P script behind the golden.reasons test: a golden hash moves only with its reason.
# The hash lines of tests/data/golden_hashes.txt and tests/data/golden/hashes.txt (comments left
# out) have a SHA-256; the last entry of tests/data/golden/moves.txt must name it, so a commit
# that changes a golden hash without appending `<sha256>  <why>` there fails.
#
# Input: SOURCE_DIR.
cmake_minimum_required(VERSION 3.22)
set(tables ${SOURCE_DIR}/tests/data/golden_hashes.txt ${SOURCE_DIR}/tests/data/golden/hashes.txt)
set(moves ${SOURCE_DIR}/tests/data/golden/moves.txt)

set(lines "")
foreach(table ${tables})
  file(STRINGS ${table} hashes REGEX "^[^#]")
  foreach(line ${hashes})
    string(APPEND lines "${line}\n")
  endforeach()
endforeach()
string(SHA256 digest "${lines}")

file(STRINGS ${moves} entries REGEX "^[0-9a-f]")
list(LENGTH entries count)
if(count EQUAL 0)
  message(FATAL_ERROR "${moves}: no entry; append `${digest}  <why the golden hashes are these>`")
endif()
list(GET entries -1 last)
if(NOT last MATCHES "^([0-9a-f]+)  +([^ ].*)$")
  message(FATAL_ERROR "${moves}: the last entry is not `<sha256>  <reason>`:\n  ${last}")
endif()
if(NOT CMAKE_MATCH_1 STREQUAL digest)
  message(FATAL_ERROR "the golden hashes moved (their lines now hash to ${digest}, "
                      "the last entry of tests/data/golden/moves.txt says ${CMAKE_MATCH_1}). "
                      "If they moved on purpose, append to that file in the same commit:\n"
                      "  ${digest}  <why the results changed>")
endif()
message("golden hashes as recorded: ${CMAKE_MATCH_2}")

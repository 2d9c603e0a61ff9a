# fuzz.repeatable: runs one fuzz target twice from the same seed and corpus, each into its own
# empty working corpus, and fails unless both runs leave the same corpus files (their names are
# the inputs' SHA-1s). What makes a run repeat is in tests/fuzz/CMakeLists.txt; this catches a
# change that brings back a thread, an exported instrumented function or a clock.
# Inputs: FUZZER (the target), WORK (a scratch folder), RUNS, OPTIONS (libFuzzer's, those of the
# fuzz.<reader> tests), SEEDS (folders), LAUNCHER (optional: the command to run the target under,
# e.g. setarch;-R); lists ';'-separated.
foreach(var FUZZER WORK RUNS OPTIONS SEEDS)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "RepeatRun.cmake: -D${var}=... is required")
  endif()
endforeach()

set(listings "")
foreach(run a b)
  file(REMOVE_RECURSE ${WORK}/${run})
  file(MAKE_DIRECTORY ${WORK}/${run}/corpus)
  execute_process(
    COMMAND ${LAUNCHER} ${FUZZER} -runs=${RUNS} ${OPTIONS} -artifact_prefix=${WORK}/${run}/
            ${WORK}/${run}/corpus ${SEEDS}
    RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE out)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "fuzz.repeatable: run ${run} of ${FUZZER} failed (${rc}):\n${out}")
  endif()
  file(GLOB units RELATIVE ${WORK}/${run}/corpus ${WORK}/${run}/corpus/*)
  list(SORT units)
  list(LENGTH units count)
  set(${run}_units "${units}")
  string(APPEND listings " ${count}")
endforeach()

if(NOT a_units STREQUAL b_units)
  message(FATAL_ERROR "fuzz.repeatable: two runs of ${FUZZER} from the same seed and corpus left "
                      "different corpora (${listings} files): something in the run depends on "
                      "threads, addresses or time (docs/testing.md, Fuzzing)")
endif()
message(STATUS "fuzz.repeatable: ${FUZZER}: the same${listings} corpus files twice")

# The determinism promise across builds: `tickfx run` built with g++ at -O0, and with clang++ and
# g++ at -O3 -march=native, must reach the same golden state hashes as this build, for
# the samples and for the golden effects of tests/data/golden/. See
# tests/scripts/BuildVariants.cmake.
#
# Not in a sanitizer build: the variants are unsanitised, so scripts/test's second pass would only
# build them all again; test_golden_hashes still checks the sanitised build against the same hashes.
if(TARGET tickfx_cli AND NOT TICKFX_SANITIZE)
  add_test(NAME determinism.compilers
    COMMAND ${CMAKE_COMMAND}
      -DSOURCE_DIR=${PROJECT_SOURCE_DIR}
      -DWORK_DIR=${PROJECT_BINARY_DIR}/variants
      -DGENERATOR=${CMAKE_GENERATOR}
      -DMAIN_TICKFX=$<TARGET_FILE:tickfx_cli>
      -DMAIN_NAME=main-${CMAKE_CXX_COMPILER_ID}-${CMAKE_BUILD_TYPE}
      -DGOLDEN_FILE=${CMAKE_CURRENT_SOURCE_DIR}/data/golden_hashes.txt
      -DGOLDEN_EFFECTS_FILE=${CMAKE_CURRENT_SOURCE_DIR}/data/golden/hashes.txt
      -P ${CMAKE_CURRENT_SOURCE_DIR}/scripts/BuildVariants.cmake)
  # It builds the CLI three times on every core: beside other tests it would slow them into their
  # timeouts. With four variants it took 249 s from scratch on 2 cores (the runs themselves about
  # 1 s a variant). The timeout leaves room for a slow CI machine.
  set_tests_properties(determinism.compilers PROPERTIES
    TIMEOUT 1500
    RUN_SERIAL TRUE
    LABELS variants)
endif()

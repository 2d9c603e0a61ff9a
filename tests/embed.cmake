# Installs tickfx into a scratch prefix and builds samples/embed against it with find_package.
if(TARGET tickfx_cli)
  add_test(NAME embed.find_package
    COMMAND ${CMAKE_COMMAND}
      -DTICKFX_BINARY_DIR=${PROJECT_BINARY_DIR}
      -DSOURCE_DIR=${PROJECT_SOURCE_DIR}
      -DEMBED_SOURCE_DIR=${PROJECT_SOURCE_DIR}/samples/embed
      -DWORK_DIR=${PROJECT_BINARY_DIR}/embed-test
      -DGENERATOR=${CMAKE_GENERATOR}
      -DCXX_COMPILER=${CMAKE_CXX_COMPILER}
      -DTICKFX_CLI=$<TARGET_FILE:tickfx_cli>
      -P ${CMAKE_CURRENT_SOURCE_DIR}/scripts/EmbedTest.cmake)
  # Judged by the script's exit code (every check ends in FATAL_ERROR), not by a line of its
  # output: ctest ignores the exit code of a test that has a PASS_REGULAR_EXPRESSION.
  set_tests_properties(embed.find_package PROPERTIES TIMEOUT 900)
endif()

# Installs tickfx into a scratch prefix and builds samples/embed against it with find_package.
add_test(NAME embed.find_package
  COMMAND ${CMAKE_COMMAND}
    -DTICKFX_BINARY_DIR=${PROJECT_BINARY_DIR}
    -DEMBED_SOURCE_DIR=${PROJECT_SOURCE_DIR}/samples/embed
    -DWORK_DIR=${PROJECT_BINARY_DIR}/embed-test
    -DGENERATOR=${CMAKE_GENERATOR}
    -DCXX_COMPILER=${CMAKE_CXX_COMPILER}
    -P ${CMAKE_CURRENT_SOURCE_DIR}/scripts/EmbedTest.cmake)
set_tests_properties(embed.find_package PROPERTIES
  PASS_REGULAR_EXPRESSION "y after 1 s: -4\\.9050 m"
  TIMEOUT 600)

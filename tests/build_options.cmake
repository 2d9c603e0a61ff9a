# With -DTICKFX_BUILD_CLI=OFF there is no tickfx_io, tickfx_cli or tickfx_app, and every test list
# below that needs one of them adds nothing: effect files, caches, checkpoints, the command line,
# the golden hashes, the compiler variants. ctest would then be green over a fraction of the suite.
# Instead this configuration gets one test that fails and names what was left out, so a green run
# always means the whole suite ran.
if(NOT TICKFX_BUILD_CLI)
  file(GLOB lists RELATIVE ${CMAKE_CURRENT_SOURCE_DIR} ${CMAKE_CURRENT_SOURCE_DIR}/*.cmake)
  list(SORT lists)
  set(left_out "")
  foreach(list_file ${lists})
    if(list_file STREQUAL "build_options.cmake")
      continue()
    endif()
    file(READ ${CMAKE_CURRENT_SOURCE_DIR}/${list_file} text)
    if(text MATCHES "TARGET tickfx_(io|cli|app)")
      list(APPEND left_out tests/${list_file})
    endif()
  endforeach()
  string(REPLACE ";" ", " left_out "${left_out}")
  string(CONCAT message "TICKFX_BUILD_CLI is OFF, so these test lists added no tests: "
                        "${left_out}. Configure with -DTICKFX_BUILD_CLI=ON to run the whole suite.")
  message(WARNING "${message}")
  # The command prints the message; FAIL_REGULAR_EXPRESSION turns that output into the failure,
  # so `ctest --output-on-failure` shows why.
  add_test(NAME build_options.cli_tests_not_built COMMAND ${CMAKE_COMMAND} -E echo "${message}")
  set_tests_properties(build_options.cli_tests_not_built PROPERTIES
    FAIL_REGULAR_EXPRESSION "TICKFX_BUILD_CLI is OFF")
endif()

# The `tickfx` command line, run as a user runs it.
if(TARGET tickfx_cli)
  tickfx_add_test(test_cli ${CMAKE_CURRENT_SOURCE_DIR}/test_cli.cpp LIBS tickfx_io)
  target_compile_definitions(test_cli PRIVATE
    TICKFX_CLI="$<TARGET_FILE:tickfx_cli>" TICKFX_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
  add_dependencies(test_cli tickfx_cli)
endif()

# The command line under faults: writes that fail, and SIGINT/SIGTERM during a run.
if(TARGET tickfx_cli)
  tickfx_add_test(test_cli_faults ${CMAKE_CURRENT_SOURCE_DIR}/test_cli_faults.cpp LIBS tickfx_io)
  target_compile_definitions(test_cli_faults PRIVATE
    TICKFX_CLI="$<TARGET_FILE:tickfx_cli>" TICKFX_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
  add_dependencies(test_cli_faults tickfx_cli)
endif()

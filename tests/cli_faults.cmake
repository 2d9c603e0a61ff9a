# The command line under faults: writes that fail, and SIGINT/SIGTERM during a run.
if(TARGET tickfx_cli)
  tickfx_add_cli_test(test_cli_faults ${CMAKE_CURRENT_SOURCE_DIR}/test_cli_faults.cpp
    LIBS tickfx_io)
endif()

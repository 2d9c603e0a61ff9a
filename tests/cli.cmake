# The `tickfx` command line, run as a user runs it.
if(TARGET tickfx_cli)
  tickfx_add_cli_test(test_cli ${CMAKE_CURRENT_SOURCE_DIR}/test_cli.cpp LIBS tickfx_io)
endif()

# Hash logs: `tickfx determinism --record` on one machine, `--compare` on another.
if(TARGET tickfx_cli)
  tickfx_add_cli_test(test_hash_log ${CMAKE_CURRENT_SOURCE_DIR}/test_hash_log.cpp LIBS tickfx_io)
endif()

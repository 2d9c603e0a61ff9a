# Hash logs: `tickfx determinism --record` on one machine, `--compare` on another.
if(TARGET tickfx_cli)
  tickfx_add_test(test_hash_log ${CMAKE_CURRENT_SOURCE_DIR}/test_hash_log.cpp LIBS tickfx_io)
  target_compile_definitions(test_hash_log PRIVATE
    TICKFX_CLI="$<TARGET_FILE:tickfx_cli>" TICKFX_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
  add_dependencies(test_hash_log tickfx_cli)
endif()

# The ThreadSanitizer build's control program (tests/tsan_canary.cpp), run by scripts/test.
if(TICKFX_THREAD_SANITIZER)
  add_executable(tsan_canary ${CMAKE_CURRENT_SOURCE_DIR}/tsan_canary.cpp)
  target_link_libraries(tsan_canary PRIVATE tickfx::tickfx)
  set_target_properties(tsan_canary PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${PROJECT_BINARY_DIR}/tests)
endif()

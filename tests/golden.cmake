# The sample effects against tests/data/golden_hashes.txt and the golden effects of
# tests/data/golden/ against its hashes.txt: the state after 2 s of ticks, bit for bit.
if(TARGET tickfx_io)
  tickfx_add_test(test_golden_hashes ${CMAKE_CURRENT_SOURCE_DIR}/test_golden_hashes.cpp
    LIBS tickfx::io)
  target_compile_definitions(test_golden_hashes PRIVATE TICKFX_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
endif()

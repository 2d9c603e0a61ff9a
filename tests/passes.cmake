tickfx_add_test(test_passes ${CMAKE_CURRENT_SOURCE_DIR}/test_passes.cpp)

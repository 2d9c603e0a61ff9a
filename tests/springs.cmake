# Spring networks and structures (fields/SpringNetwork, particles/Structure).
tickfx_add_test(test_springs ${CMAKE_CURRENT_SOURCE_DIR}/test_springs.cpp)

tickfx_add_test(test_passes ${CMAKE_CURRENT_SOURCE_DIR}/test_passes.cpp)
# Fused frames: advection included (fields/AnalyticField, in tickfx_vdb).
tickfx_add_test(test_fused_ticks ${CMAKE_CURRENT_SOURCE_DIR}/test_fused_ticks.cpp LIBS tickfx::vdb)

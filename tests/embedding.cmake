# The embedding API (io/effect/EffectLoader.h, render copies, host executors), as a host calls it.
if(TARGET tickfx_io)
  tickfx_add_test(test_embedding ${CMAKE_CURRENT_SOURCE_DIR}/test_embedding.cpp LIBS tickfx::effects)
  target_compile_definitions(test_embedding PRIVATE TICKFX_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
endif()

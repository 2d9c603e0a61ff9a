if(TARGET tickfx_app)
  tickfx_add_test(test_determinism ${CMAKE_CURRENT_SOURCE_DIR}/test_determinism.cpp LIBS tickfx_app)
  target_compile_definitions(test_determinism PRIVATE TICKFX_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
endif()

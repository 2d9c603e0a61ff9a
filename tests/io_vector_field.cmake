# [[forces]] of type "vector_field" in effect files: parsing, advection rules, overrides, lint,
# building (io/effect/VectorFieldSource). Named io* so that `ctest -R io` selects it; its .vdb files go
# into a temporary directory of its own.
if(TARGET tickfx_io)
  tickfx_add_test(test_io_vector_field ${CMAKE_CURRENT_SOURCE_DIR}/test_io_vector_field.cpp
    LIBS tickfx::io)
  target_compile_definitions(test_io_vector_field PRIVATE TICKFX_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
endif()

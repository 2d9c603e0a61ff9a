# Structures (rope, cloth, cluster) in effect files: parsing and its messages, the builder, lint,
# and the samples that use them. Named io* so that `ctest -R io` selects them.
if(TARGET tickfx_io)
  tickfx_add_test(test_io_structures ${CMAKE_CURRENT_SOURCE_DIR}/test_io_structures.cpp
    LIBS tickfx::io)
  target_compile_definitions(test_io_structures PRIVATE TICKFX_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
endif()

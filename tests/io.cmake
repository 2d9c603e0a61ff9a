# Effect files (io/): validation and its messages, lint, --set overrides, the builder, samples.
# Suites are named io* so that `ctest -R io` selects them.
if(TARGET tickfx_io)
  foreach(area parser lint overrides builder samples)
    tickfx_add_test(test_io_${area} ${CMAKE_CURRENT_SOURCE_DIR}/test_io_${area}.cpp LIBS tickfx::io)
    target_compile_definitions(test_io_${area} PRIVATE TICKFX_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
  endforeach()
endif()

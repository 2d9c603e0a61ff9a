# The core's tests (particles/, integrators/, fields/): one executable per area.
foreach(area integrators oscillator driver frame_time pool emitter math state_hash nonfinite assert)
  tickfx_add_test(test_${area} ${CMAKE_CURRENT_SOURCE_DIR}/test_${area}.cpp)
endforeach()

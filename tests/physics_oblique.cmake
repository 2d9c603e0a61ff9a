# Forces and integrators off the axes (tests/ObliqueTestSupport.h): the integrator study's fall
# and oscillator along an oblique axis, component by component.
tickfx_add_test(test_integrators_oblique ${CMAKE_CURRENT_SOURCE_DIR}/test_integrators_oblique.cpp)

# Forces and integrators off the axes (tests/ObliqueTestSupport.h): every force module against its
# closed form on all three axes under all six schemes, and the integrator study's fall and
# oscillator along an oblique axis. The field cases bake their grids in memory (tickfx::vdb).
tickfx_add_test(test_integrators_oblique ${CMAKE_CURRENT_SOURCE_DIR}/test_integrators_oblique.cpp)
if(TARGET tickfx_vdb)
  tickfx_add_test(test_forces_oblique ${CMAKE_CURRENT_SOURCE_DIR}/test_forces_oblique.cpp
    LIBS tickfx::vdb)
endif()

# The integrator study (app/IntegratorStudy.cpp) checked against its closed-form solutions. The
# study source is compiled in directly: app/ is built only with the command line.
tickfx_add_test(test_study
  ${CMAKE_CURRENT_SOURCE_DIR}/test_study.cpp
  ${PROJECT_SOURCE_DIR}/app/IntegratorStudy.cpp)

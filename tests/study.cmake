# The integrator study (app/IntegratorStudy.cpp) checked against its closed-form solutions. The
# study source is compiled in directly: app/ is built only with the command line.
tickfx_add_test(test_study
  ${CMAKE_CURRENT_SOURCE_DIR}/test_study.cpp
  ${PROJECT_SOURCE_DIR}/app/IntegratorStudy.cpp
  LIBS tickfx::io)
# The progress bar of the long commands (app/ProgressLine.cpp, compiled in directly).
tickfx_add_test(test_progress
  ${CMAKE_CURRENT_SOURCE_DIR}/test_progress.cpp
  ${PROJECT_SOURCE_DIR}/app/ProgressLine.cpp)

# Checkpoints (io/cache/Checkpoint): resume reaches the uninterrupted hash; bad files are refused whole.
if(TARGET tickfx_io)
  tickfx_add_test(test_io_checkpoint ${CMAKE_CURRENT_SOURCE_DIR}/test_io_checkpoint.cpp LIBS tickfx::io)
endif()

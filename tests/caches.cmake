if(TARGET tickfx_io)
  tickfx_add_test(test_io_caches ${CMAKE_CURRENT_SOURCE_DIR}/test_io_caches.cpp
                  ${CMAKE_CURRENT_SOURCE_DIR}/test_background_writer.cpp LIBS tickfx_io tickfx_app)
endif()

# Preview renders (io/preview/): the camera, the splats and the PNG bytes.
tickfx_add_test(test_preview ${CMAKE_CURRENT_SOURCE_DIR}/test_preview.cpp LIBS tickfx_preview)

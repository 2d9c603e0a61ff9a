# Preview renders (app/preview/): the camera, the splats and the PNG bytes.
tickfx_add_test(test_preview ${CMAKE_CURRENT_SOURCE_DIR}/test_preview.cpp LIBS tickfx_preview)
# What a preview draws besides splats (lines, grid, legend), colouring, pscale, cache folders.
tickfx_add_test(test_preview_scene ${CMAKE_CURRENT_SOURCE_DIR}/test_preview_scene.cpp
                LIBS tickfx_preview tickfx_app)
target_compile_definitions(test_preview_scene PRIVATE TICKFX_SOURCE_DIR="${PROJECT_SOURCE_DIR}")

# GIF flipbooks (app/preview/GifFlipbook): read back through giflib's own decoder.
find_package(GIF REQUIRED)
tickfx_add_test(test_gif_flipbook ${CMAKE_CURRENT_SOURCE_DIR}/test_gif_flipbook.cpp
                LIBS tickfx_preview GIF::GIF)

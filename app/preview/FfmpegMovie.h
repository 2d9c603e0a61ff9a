// A preview sequence encoded as an MP4 by Debian's ffmpeg, when it is installed.
#pragma once

#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>

#include "app/preview/SplatImage.h"

namespace tickfx::preview {

/// The ffmpeg to run: $TICKFX_FFMPEG when set, else `ffmpeg` on PATH; nothing when that is not
/// an executable file.
std::optional<std::filesystem::path> findFfmpeg();

/// Frames piped to an ffmpeg process as raw RGB and encoded as H.264 in an MP4 (yuv420p, which
/// every player reads; an odd width or height is padded by one pixel). The movie is written to a
/// temporary beside `path` and renamed on finish(), so a failure leaves no partial movie.
class FfmpegMovie {
 public:
  /// Starts `ffmpeg` for frames of width × height at `fps` frames per second. Throws
  /// std::runtime_error when the process cannot be started.
  FfmpegMovie(const std::filesystem::path& ffmpeg, const std::filesystem::path& path, int width,
              int height, double fps);
  ~FfmpegMovie();
  FfmpegMovie(const FfmpegMovie&) = delete;
  FfmpegMovie& operator=(const FfmpegMovie&) = delete;

  /// Sends one frame (width × height, else std::invalid_argument).
  void add(const SplatImage& image);
  /// Waits for ffmpeg and renames the movie into place. Throws std::runtime_error with ffmpeg's
  /// exit status when it failed (its own messages went to stderr).
  void finish();

 private:
  std::FILE* pipe_ = nullptr;
  std::filesystem::path path_, partial_;
  int width_, height_;
};

}  // namespace tickfx::preview

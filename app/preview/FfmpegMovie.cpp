#include "app/preview/FfmpegMovie.h"

#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <cstdlib>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace tickfx::preview {
namespace {

bool executable(const std::filesystem::path& p) {
  std::error_code error;
  return std::filesystem::is_regular_file(p, error) && ::access(p.c_str(), X_OK) == 0;
}

// Single quotes for /bin/sh, which popen runs.
std::string quoted(const std::string& text) {
  std::string out = "'";
  for (const char c : text) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

}  // namespace

std::optional<std::filesystem::path> findFfmpeg() {
  if (const char* chosen = std::getenv("TICKFX_FFMPEG")) {
    if (executable(chosen)) return std::filesystem::path(chosen);
    return std::nullopt;
  }
  const char* path = std::getenv("PATH");
  std::stringstream dirs(path != nullptr ? path : "/usr/bin:/bin");
  std::string dir;
  while (std::getline(dirs, dir, ':')) {
    const std::filesystem::path candidate =
        std::filesystem::path(dir.empty() ? "." : dir) / "ffmpeg";
    if (executable(candidate)) return candidate;
  }
  return std::nullopt;
}

FfmpegMovie::FfmpegMovie(const std::filesystem::path& ffmpeg, const std::filesystem::path& path,
                         int width, int height, double fps)
    : path_(path), partial_(path.string() + ".partial.mp4"), width_(width), height_(height) {
  char rate[32];
  std::snprintf(rate, sizeof rate, "%.6g", fps);
  const std::string command =
      quoted(ffmpeg.string()) + " -loglevel error -y -f rawvideo -pix_fmt rgb24 -s " +
      std::to_string(width) + "x" + std::to_string(height) + " -r " + rate +
      " -i - -an -c:v libx264 -pix_fmt yuv420p -vf 'pad=ceil(iw/2)*2:ceil(ih/2)*2' -movflags "
      "+faststart " +
      quoted(partial_.string());
  // An ffmpeg that dies must give an error message, not kill this process at the next write.
  std::signal(SIGPIPE, SIG_IGN);
  pipe_ = ::popen(command.c_str(), "w");
  if (pipe_ == nullptr) throw std::runtime_error("cannot start " + ffmpeg.string());
}

FfmpegMovie::~FfmpegMovie() {
  if (pipe_ != nullptr) {
    ::pclose(pipe_);
    std::error_code ignored;
    std::filesystem::remove(partial_, ignored);
  }
}

void FfmpegMovie::add(const SplatImage& image) {
  if (image.width() != width_ || image.height() != height_) {
    throw std::invalid_argument("FfmpegMovie::add: a frame of another size");
  }
  const std::vector<std::uint8_t> bytes = image.rgb8();
  // A short write means ffmpeg has gone; finish() reports its status.
  (void)std::fwrite(bytes.data(), 1, bytes.size(), pipe_);
}

void FfmpegMovie::finish() {
  const int status = ::pclose(pipe_);
  pipe_ = nullptr;
  std::error_code error;
  if (status != 0) {
    std::filesystem::remove(partial_, error);
    const std::string how = WIFEXITED(status) ? "exit status " + std::to_string(WEXITSTATUS(status))
                                              : "status " + std::to_string(status);
    throw std::runtime_error(path_.string() + ": error: ffmpeg failed (" + how +
                             "); no movie written");
  }
  std::filesystem::rename(partial_, path_, error);
  if (error) {
    throw std::runtime_error(path_.string() + ": error: cannot rename the movie into place (" +
                             error.message() + ")");
  }
}

}  // namespace tickfx::preview

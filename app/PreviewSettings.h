// What `tickfx preview` is asked to do: its command line, read and checked before anything runs.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "app/Arguments.h"
#include "app/preview/FrameRenderer.h"
#include "app/preview/PinholeCamera.h"
#include "app/preview/SceneGuides.h"

namespace tickfx::app {

/// An image's size in pixels.
struct ImageSize {
  int width = 1280;
  int height = 720;
};

/// Everything the command line asks for, read and checked before anything runs.
struct PreviewSettings {
  std::string input;
  std::vector<std::string> overrides;
  std::filesystem::path out;
  ImageSize size;
  std::string colour;
  std::optional<std::string> frames;
  long long every = 1;
  preview::SplatSize splatSize;
  std::optional<Eigen::Vector3d> eye, target;
  double fov = 40.0;
  preview::UpAxis up = preview::UpAxis::Y;
  bool guides = true;
  bool sheet = false;
  bool gif = false;
  std::optional<std::filesystem::path> ffmpeg;  // --mp4
  std::size_t keepBytes = std::size_t{1} << 30;

  /// The camera at --camera looking at `look`; a camera that sees nothing is a usage error.
  preview::PinholeCamera cameraAt(const Eigen::Vector3d& look, int width, int height) const;
};

/// Reads every option of `tickfx preview` (after --help) and its input; UsageError for a bad one.
PreviewSettings readPreviewSettings(Arguments& args);

}  // namespace tickfx::app

// What a preview draws besides the particles: the ground grid, axis marks, the colour legend
// and the caption, so that a viewer sees scale, up, what the colours mean and what frame it is.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string_view>

#include "app/preview/PinholeCamera.h"
#include "app/preview/SplatImage.h"

namespace tickfx::preview {

/// The world axis that points up: y (tickfx's and Houdini's convention) or z (Blender's).
enum class UpAxis { Y, Z };

/// The unit vector of `up`.
Eigen::Vector3d upVector(UpAxis up);

/// Lines on the ground plane (the up coordinate 0) every `spacing` metres, over [lo, hi] on the
/// two ground axes (x and z when y is up, x and y when z is up).
struct GroundGrid {
  UpAxis up = UpAxis::Y;
  double spacing = 1.0;  // metres
  Eigen::Vector2d lo = Eigen::Vector2d::Zero();
  Eigen::Vector2d hi = Eigen::Vector2d::Zero();

  /// Lines a side at most; a wider footprint takes a coarser spacing.
  static constexpr int kMaxLines = 100;

  /// A grid under the box [lo, hi] (metres): 1 m apart over the box's footprint rounded out to
  /// whole metres and one more each side; 10 m, 100 m, ... apart when 1 m would draw more than
  /// kMaxLines lines along an axis. Nothing for a footprint wider than kMaxLines · 10¹² m (a run
  /// that has blown up) or not finite.
  static std::optional<GroundGrid> under(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi,
                                         UpAxis up);
};

/// Draws `grid` in a dim grey, the parts in front of the camera.
void drawGroundGrid(SplatImage& image, const PinholeCamera& camera, const GroundGrid& grid);

/// Draws the world axes from the origin, `length` metres each: x red, y green, z blue (the
/// colours DCCs use), each labelled with its letter at its tip.
void drawAxisMarks(SplatImage& image, const PinholeCamera& camera, double length);

/// Draws a legend strip in the bottom-left corner: viridis from `lo` (left) to `hi` (right), both
/// ends labelled, `title` ("speed m/s") above; text at `scale` (PixelFont).
void drawLegend(SplatImage& image, std::string_view title, double lo, double hi, int scale);

/// Burns `text` into the top-left corner, light on a dark box.
void drawCaption(SplatImage& image, std::string_view text, int scale);

}  // namespace tickfx::preview

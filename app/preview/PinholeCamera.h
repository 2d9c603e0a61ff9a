// The camera of preview renders: a pinhole looking at a target.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <utility>

namespace tickfx::preview {

/// Where a point lands in the image: pixel coordinates (x to the right, y down, pixel (i, j)
/// covering [i, i + 1) × [j, j + 1)) and its depth along the view axis (metres).
struct Projected {
  double x = 0.0;
  double y = 0.0;
  double depth = 0.0;
};

/// A pinhole camera at `eye` looking at `target`, `up` the image's up, a vertical field of view
/// in degrees, and an image of width × height pixels. Positions are metres.
class PinholeCamera {
 public:
  /// Throws std::invalid_argument for a field of view outside (0, 180) degrees, an image with no
  /// pixel, an eye on the target, or an up along the view.
  PinholeCamera(const Eigen::Vector3d& eye, const Eigen::Vector3d& target,
                const Eigen::Vector3d& up, double fovDegrees, int width, int height);

  /// A camera that sees the box [lo, hi] whole, with `margin` (a fraction of its size) to spare
  /// on every side: it looks at the box's centre from in front, a little above and to the right
  /// (as `up` sees it), from far enough that the box's bounding sphere fits the narrower field of
  /// view.
  static PinholeCamera framing(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi,
                               const Eigen::Vector3d& up, double fovDegrees, int width, int height,
                               double margin = 0.1);

  /// Where `p` lands, or nothing when it is not in front of the camera (depth below kNear).
  std::optional<Projected> project(const Eigen::Vector3d& p) const;
  /// The part of the segment [a, b] in front of the camera (depth at least kNear), projected;
  /// nothing when none of it is.
  std::optional<std::pair<Projected, Projected>> projectSegment(const Eigen::Vector3d& a,
                                                                const Eigen::Vector3d& b) const;
  /// Pixels one metre spans, across the view, at `depth` metres.
  double pixelsPerMetre(double depth) const { return focal_ / depth; }

  int width() const { return width_; }
  int height() const { return height_; }
  const Eigen::Vector3d& eye() const { return eye_; }

  /// Points nearer than this (metres along the view) are not drawn.
  static constexpr double kNear = 1e-3;

 private:
  Eigen::Vector3d eye_, forward_, right_, up_;
  double focal_;  // pixels: half the image height over tan(fov / 2)
  int width_, height_;
};

}  // namespace tickfx::preview

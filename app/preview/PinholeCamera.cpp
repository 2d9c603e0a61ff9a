#include "app/preview/PinholeCamera.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace tickfx::preview {
namespace {

constexpr double kPi = 3.14159265358979323846;

double radians(double degrees) { return degrees * kPi / 180.0; }

}  // namespace

PinholeCamera::PinholeCamera(const Eigen::Vector3d& eye, const Eigen::Vector3d& target,
                             const Eigen::Vector3d& up, double fovDegrees, int width, int height)
    : eye_(eye), width_(width), height_(height) {
  if (!(fovDegrees > 0.0 && fovDegrees < 180.0)) {
    throw std::invalid_argument("the field of view must be in (0, 180) degrees");
  }
  if (width <= 0 || height <= 0) throw std::invalid_argument("the image has no pixel");
  const Eigen::Vector3d view = target - eye;
  if (!(view.norm() > 0.0)) throw std::invalid_argument("the camera is on the point it looks at");
  forward_ = view.normalized();
  const Eigen::Vector3d side = forward_.cross(up);
  if (!(side.norm() > 1e-9 * up.norm())) {
    throw std::invalid_argument("the camera's up is along its view");
  }
  right_ = side.normalized();
  up_ = right_.cross(forward_);
  focal_ = 0.5 * height / std::tan(0.5 * radians(fovDegrees));
}

PinholeCamera PinholeCamera::framing(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi,
                                     const Eigen::Vector3d& up, double fovDegrees, int width,
                                     int height, double margin) {
  const Eigen::Vector3d centre = 0.5 * (lo + hi);
  // A box of no size (one particle) is framed as a metre across.
  const double radius = std::max(0.5 * (hi - lo).norm(), 0.5) * (1.0 + margin);
  const double vertical = radians(fovDegrees);
  const double horizontal = 2.0 * std::atan(std::tan(0.5 * vertical) * width / height);
  const double distance = radius / std::sin(0.5 * std::min(vertical, horizontal));
  // In front (a horizontal axis perpendicular to up), a third of the way up and a quarter right.
  const Eigen::Vector3d u = up.normalized();
  Eigen::Vector3d front = std::abs(u.z()) < 0.9 ? Eigen::Vector3d(Eigen::Vector3d::UnitZ())
                                                : Eigen::Vector3d(-Eigen::Vector3d::UnitY());
  front = (front - front.dot(u) * u).normalized();
  const Eigen::Vector3d right = u.cross(front).normalized();
  const Eigen::Vector3d direction = (front + 0.35 * u + 0.25 * right).normalized();
  return PinholeCamera(centre + distance * direction, centre, up, fovDegrees, width, height);
}

std::optional<Projected> PinholeCamera::project(const Eigen::Vector3d& p) const {
  const Eigen::Vector3d d = p - eye_;
  const double depth = d.dot(forward_);
  if (!(depth >= kNear)) return std::nullopt;
  const double s = focal_ / depth;
  return Projected{0.5 * width_ + s * d.dot(right_), 0.5 * height_ - s * d.dot(up_), depth};
}

std::optional<std::pair<Projected, Projected>> PinholeCamera::projectSegment(
    const Eigen::Vector3d& a, const Eigen::Vector3d& b) const {
  const double da = (a - eye_).dot(forward_), db = (b - eye_).dot(forward_);
  if (!(da >= kNear) && !(db >= kNear)) return std::nullopt;
  // Cut the segment where it crosses a plane just past the near one (twice kNear, so that the
  // rounded cut is surely in front), so a line running past the camera keeps its visible part.
  const auto cut = [&](const Eigen::Vector3d& from, double dFrom, const Eigen::Vector3d& to,
                       double dTo) {
    return Eigen::Vector3d(from + (to - from) * ((2.0 * kNear - dFrom) / (dTo - dFrom)));
  };
  const std::optional<Projected> pa = project(da >= kNear ? a : cut(a, da, b, db));
  const std::optional<Projected> pb = project(db >= kNear ? b : cut(b, db, a, da));
  if (!pa || !pb) return std::nullopt;
  return std::pair{*pa, *pb};
}

}  // namespace tickfx::preview

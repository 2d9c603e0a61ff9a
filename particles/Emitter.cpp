#include "particles/Emitter.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "particles/DetMath.h"
#include "particles/ExactTime.h"
#include "particles/Random.h"

namespace tickfx {
namespace {

constexpr std::int64_t kMicros = 1'000'000;

// Two unit vectors completing `n` (unit) to a right-handed orthonormal basis, without a branch
// on a threshold that a tiny change of n could flip (Duff et al. 2017).
void basis(const Eigen::Vector3d& n, Eigen::Vector3d& b1, Eigen::Vector3d& b2) {
  const double sign = std::copysign(1.0, n.z());
  const double a = -1.0 / (sign + n.z());
  const double b = n.x() * n.y() * a;
  b1 = Eigen::Vector3d(1.0 + sign * n.x() * n.x() * a, sign * b, -sign * n.x());
  b2 = Eigen::Vector3d(b, sign + n.y() * n.y() * a, -n.y());
}

void require(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument(what);
}

}  // namespace

Emitter::Emitter(EmitterSettings settings, std::uint32_t index, std::int64_t stepRateHz)
    : s_(std::move(settings)), index_(index), stepRate_(stepRateHz) {
  require(stepRateHz > 0, "step rate must be positive");
  require(std::isfinite(s_.rate) && s_.rate >= 0.0 && s_.rate <= 1.0e9,
          "emitter rate must be in [0, 1e9] particles per second");
  require(std::isfinite(s_.start) && s_.start >= 0.0, "emitter start must be a time >= 0");
  require(!std::isnan(s_.stop) && s_.stop >= s_.start, "emitter stop must not be before start");
  require(s_.direction.allFinite() && s_.direction.norm() > 0.0,
          "emitter direction must not be zero");
  require(std::isfinite(s_.speed) && s_.speed >= 0.0, "emitter speed must be >= 0");
  require(s_.speedJitter >= 0.0 && s_.speedJitter <= 1.0, "speed jitter must be in [0, 1]");
  require(s_.spreadDegrees >= 0.0 && s_.spreadDegrees <= 180.0,
          "spread must be in [0, 180] degrees");
  require(s_.lifetime > 0.0, "lifetime must be > 0");
  require(s_.lifetimeJitter >= 0.0 && s_.lifetimeJitter < 1.0, "lifetime jitter must be in [0, 1)");
  require(s_.mass > 0.0, "mass must be > 0");
  require(s_.position.allFinite(), "emitter position must be finite");
  s_.direction.normalize();
  if (auto* disc = std::get_if<DiscShape>(&s_.shape)) {
    require(disc->normal.allFinite() && disc->normal.norm() > 0.0, "disc normal must not be zero");
    disc->normal.normalize();
  }
  if (const auto* list = std::get_if<PointListShape>(&s_.shape)) {
    require(!list->positions.empty(), "a point list needs at least one point");
    require(list->velocities.empty() || list->velocities.size() == list->positions.size(),
            "a point list has one velocity per point or none");
    for (const Eigen::Vector3f& p : list->positions)
      require(p.allFinite(), "point list positions must be finite");
    for (const Eigen::Vector3f& v : list->velocities)
      require(v.allFinite(), "point list velocities must be finite");
  }
  require(s_.start <= 1.0e9 && (std::isinf(s_.stop) || s_.stop <= 1.0e9),
          "emitter start and stop must be at most 1e9 s");
  rate_ = EmissionRate(std::llround(s_.rate * static_cast<double>(kMicros)), s_.start, s_.stop,
                       stepRate_);
  for (const Burst& b : s_.bursts) {
    require(std::isfinite(b.time) && b.time >= 0.0, "burst time must be >= 0");
    burstTicks_.emplace_back(exact::tickAtOrAfter(b.time, stepRate_), b.count);
  }
  std::stable_sort(burstTicks_.begin(), burstTicks_.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
}

std::uint64_t Emitter::rateCountBefore(std::int64_t tick) const {
  return tick <= 0 ? 0 : rate_.madeThrough(tick - 1);
}

std::uint64_t Emitter::serialBefore(std::int64_t tick) const {
  std::uint64_t serial = rateCountBefore(tick);
  for (const auto& [burstTick, count] : burstTicks_) {
    if (burstTick < tick) serial += count;
  }
  return serial;
}

std::uint64_t Emitter::emit(ParticlePool& pool, std::uint64_t seed, std::int64_t tick) const {
  const std::uint64_t first = serialBefore(tick);
  const std::uint64_t last = serialBefore(tick + 1);
  // Particles the pool has no room for are counted, not sampled.
  const std::uint64_t room = pool.maxParticles() - pool.size();
  const std::uint64_t tried = std::min<std::uint64_t>(last - first, room);
  for (std::uint64_t serial = first; serial < first + tried; ++serial)
    pool.spawn(sample(seed, serial), tick);
  pool.refuseSpawns(last - first - tried);
  return last - first;
}

ParticleInit Emitter::sample(std::uint64_t seed, std::uint64_t serial) const {
  auto uniform = [&](RandomPurpose purpose) {
    return randomUniform(RandomKey{seed, index_, serial, static_cast<std::uint32_t>(purpose)});
  };
  constexpr double kTwoPi = 2.0 * det::kPi;

  Eigen::Vector3d offset = Eigen::Vector3d::Zero();
  if (const auto* sphere = std::get_if<SphereShape>(&s_.shape)) {
    const double z = 1.0 - 2.0 * uniform(RandomPurpose::PositionU);
    const double rxy = std::sqrt(std::max(0.0, 1.0 - z * z));
    const double phi = kTwoPi * uniform(RandomPurpose::PositionV);
    const double r = sphere->surface
                         ? sphere->radius
                         : sphere->radius * det::cbrt(uniform(RandomPurpose::PositionW));
    offset = r * Eigen::Vector3d(rxy * det::cos(phi), rxy * det::sin(phi), z);
  } else if (const auto* box = std::get_if<BoxShape>(&s_.shape)) {
    offset = Eigen::Vector3d(uniform(RandomPurpose::PositionU) - 0.5,
                             uniform(RandomPurpose::PositionV) - 0.5,
                             uniform(RandomPurpose::PositionW) - 0.5)
                 .cwiseProduct(box->size);
  } else if (const auto* disc = std::get_if<DiscShape>(&s_.shape)) {
    Eigen::Vector3d b1, b2;
    basis(disc->normal, b1, b2);
    const double r = disc->radius * std::sqrt(uniform(RandomPurpose::PositionU));
    const double phi = kTwoPi * uniform(RandomPurpose::PositionV);
    offset = (r * det::cos(phi)) * b1 + (r * det::sin(phi)) * b2;
  }

  Eigen::Vector3d dir = s_.direction;
  if (s_.spreadDegrees > 0.0) {
    // Uniform over the spherical cap of half-angle `spread` around the direction.
    Eigen::Vector3d b1, b2;
    basis(s_.direction, b1, b2);
    const double cosMax = det::cos(s_.spreadDegrees * (det::kPi / 180.0));
    const double cosT = 1.0 - uniform(RandomPurpose::DirectionU) * (1.0 - cosMax);
    const double sinT = std::sqrt(std::max(0.0, 1.0 - cosT * cosT));
    const double phi = kTwoPi * uniform(RandomPurpose::DirectionV);
    dir = (sinT * det::cos(phi)) * b1 + (sinT * det::sin(phi)) * b2 + cosT * s_.direction;
  }
  const double speed =
      s_.speed * (1.0 + s_.speedJitter * (2.0 * uniform(RandomPurpose::Speed) - 1.0));
  const double life =
      s_.lifetime * (1.0 + s_.lifetimeJitter * (2.0 * uniform(RandomPurpose::Lifetime) - 1.0));

  ParticleInit init;
  init.position = (s_.position + offset).cast<float>();
  init.velocity = (speed * dir).cast<float>();
  if (const auto* list = std::get_if<PointListShape>(&s_.shape)) {
    const std::size_t point = serial % list->positions.size();
    const Eigen::Vector3f& p = list->positions[point];
    // In float: the point is float already, and widening it to double to add the offset would be
    // the float → double → float round trip that g++ 12's vectoriser may fold away in some lanes.
    // The offset is rounded to float once. At the origin the point is kept as it is (adding +0.0
    // would turn a −0.0 coordinate into +0.0).
    init.position = s_.position.isZero(0.0) ? p : Eigen::Vector3f(s_.position.cast<float>() + p);
    if (!list->velocities.empty()) init.velocity = list->velocities[point];
  }
  init.lifetime = static_cast<float>(life);
  init.mass = static_cast<float>(s_.mass);
  return init;
}

}  // namespace tickfx

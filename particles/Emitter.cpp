#include "particles/Emitter.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "particles/Assert.h"
#include "particles/DetMath.h"
#include "particles/ExactTime.h"
#include "particles/ParallelFor.h"
#include "particles/Random.h"
#include "particles/SpawnBatch.h"

namespace tickfx {
namespace {

// Rows emit() writes (spawnRows) before finishing them (ParticlePool::finishRows), while they are
// still in the cache.
constexpr std::size_t kSpawnBatchRows = 256;

// Two unit vectors completing `n` (unit) to a right-handed orthonormal basis, without a branch
// on a threshold that a tiny change of n could flip (Duff et al. 2017).
void basis(const Eigen::Vector3d& n, Eigen::Vector3d& b1, Eigen::Vector3d& b2) {
  const double sign = std::copysign(1.0, n.z());
  const double a = -1.0 / (sign + n.z());
  const double b = n.x() * n.y() * a;
  b1 = Eigen::Vector3d(1.0 + sign * n.x() * n.x() * a, sign * b, -sign * n.x());
  b2 = Eigen::Vector3d(b, sign + n.y() * n.y() * a, -n.y());
}

void validateSub(const EmitterSettings& e, SettingProblems& out) {
  const SubEmitterSettings& sub = e.sub;
  if (sub.parent.empty()) {
    if (sub.on != EmitterEvent::None) {
      out.push_back({"on", "is set without a parent", "a parent emitter with on"});
    }
    return;
  }
  if (sub.on == EmitterEvent::None) {
    out.push_back({"on", "is missing", "\"birth\", \"death\" or \"collision\""});
  }
  if (e.rate != 0.0 || !e.bursts.empty()) {
    out.push_back({e.rate != 0.0 ? "rate" : "bursts", "is set on a sub-emitter",
                   "no rate and no bursts: a sub-emitter emits at its parent's events"});
  }
  if (std::holds_alternative<PointListShape>(e.shape)) {
    out.push_back({"file", "is set on a sub-emitter", "a shape around the event's position"});
  }
  if (sub.countMin > sub.countMax || sub.countMax > 1'000'000) {
    out.push_back({"count_range",
                   "[" + std::to_string(sub.countMin) + ", " + std::to_string(sub.countMax) +
                       "] is out of range",
                   "[a, b] with 0 <= a <= b <= 1000000"});
  }
  if (!(sub.inheritVelocity >= 0.0 && sub.inheritVelocity <= 1.0)) {
    out.push_back({"inherit_velocity", settingNumber(sub.inheritVelocity) + " is out of range",
                   "a fraction from 0 to 1"});
  }
  if (sub.alongNormal && sub.on != EmitterEvent::Collision) {
    out.push_back({"direction", "\"normal\" needs on = \"collision\"",
                   "a direction [x, y, z], or \"normal\" on a collision"});
  }
  for (std::size_t i = 0; i < sub.inherit.size(); ++i) {
    for (std::size_t j = 0; j < i; ++j) {
      if (sub.inherit[i] == sub.inherit[j]) {
        out.push_back({"inherit." + std::to_string(i), "names " + sub.inherit[i] + " twice",
                       "each attribute once"});
      }
    }
  }
}

}  // namespace

SettingProblems EmitterSettings::validate() const {
  SettingProblems out;
  const auto check = [&](bool ok, const std::string& key, double value,
                         const std::string& expected) {
    if (!ok) out.push_back({key, settingNumber(value) + " is out of range", expected});
  };
  check(std::isfinite(rate) && rate >= 0.0 && rate <= 1.0e9, "rate", rate,
        "particles per second, a number from 0 to 1e9");
  check(std::isfinite(start) && start >= 0.0 && start <= 1.0e9, "start", start,
        "seconds, a number from 0 to 1e9");
  if (std::isfinite(stop) && stop > 1.0e9) {
    out.push_back(
        {"stop", settingNumber(stop) + " is out of range", "seconds, a number from start to 1e9"});
  } else if (!(stop >= start)) {  // infinity: never stops
    out.push_back({"stop",
                   std::isnan(stop)
                       ? "nan is not a time"
                       : settingNumber(stop) + " is before start = " + settingNumber(start),
                   "seconds, a number from start on"});
  }
  checkDirection(direction, "direction", out);
  check(std::isfinite(speed) && speed >= 0.0, "speed", speed,
        "metres per second, a finite number >= 0");
  check(speedJitter >= 0.0 && speedJitter <= 1.0, "speed_jitter", speedJitter,
        "a fraction from 0 to 1");
  check(spreadDegrees >= 0.0 && spreadDegrees <= 180.0, "spread", spreadDegrees,
        "degrees, a number from 0 to 180");
  check(lifetime > 0.0, "lifetime", lifetime, "seconds, a number > 0");
  check(lifetimeJitter >= 0.0 && lifetimeJitter < 1.0, "lifetime_jitter", lifetimeJitter,
        "a fraction >= 0 and < 1");
  check(mass > 0.0, "mass", mass, "kilograms, a number > 0");
  if (!position.allFinite()) {
    out.push_back({"position", "is not finite", "[x, y, z] in metres, finite numbers"});
  }
  if (const auto* disc = std::get_if<DiscShape>(&shape))
    checkDirection(disc->normal, "normal", out);
  if (const auto* list = std::get_if<PointListShape>(&shape)) {
    const auto bad = [&](const std::string& what, const std::string& expected) {
      out.push_back({"file", what, expected});
    };
    if (list->positions.empty()) bad("holds no points", "at least one point");
    if (!list->velocities.empty() && list->velocities.size() != list->positions.size()) {
      bad("has " + std::to_string(list->velocities.size()) + " velocities for " +
              std::to_string(list->positions.size()) + " points",
          "one velocity per point, or none");
    }
    for (const Eigen::Vector3f& p : list->positions) {
      if (!p.allFinite()) {
        bad("has a point that is not finite", "points of finite coordinates");
        break;
      }
    }
    for (const Eigen::Vector3f& v : list->velocities) {
      if (!v.allFinite()) {
        bad("has a velocity that is not finite", "velocities of finite coordinates");
        break;
      }
    }
  }
  validateSub(*this, out);
  for (std::size_t i = 0; i < attributes.size(); ++i) {
    for (SettingProblem p : attributes[i].validate()) {
      p.key = "attributes." + attributes[i].name + (p.key == "value" ? "" : "." + p.key);
      out.push_back(std::move(p));
    }
    for (std::size_t j = 0; j < i; ++j) {
      if (attributes[j].name == attributes[i].name) {
        out.push_back({"attributes." + attributes[i].name, "is declared twice", "each once"});
      }
    }
    for (const std::string& inherited : sub.inherit) {
      if (inherited == attributes[i].name) {
        out.push_back({"attributes." + inherited, "is also inherited from the parent",
                       "an attribute declared or inherited, not both"});
      }
    }
  }
  for (std::size_t i = 0; i < bursts.size(); ++i) {
    check(std::isfinite(bursts[i].time) && bursts[i].time >= 0.0 && bursts[i].time <= 1.0e9,
          "bursts." + std::to_string(i) + ".time", bursts[i].time,
          "seconds, a number from 0 to 1e9");
  }
  return out;
}

Emitter::Emitter(EmitterSettings settings, std::uint32_t index, std::int64_t stepRateHz)
    : s_(std::move(settings)), index_(index), stepRate_(stepRateHz) {
  if (stepRateHz <= 0) throw std::invalid_argument("step rate must be positive");
  throwIfAny("emitter", s_.validate());
  // Both normalise in double: validate() made sure they can.
  s_.direction.normalize();
  if (auto* disc = std::get_if<DiscShape>(&s_.shape)) {
    disc->normal.normalize();
    basis(disc->normal, discB1_, discB2_);
  }
  basis(s_.direction, directionB1_, directionB2_);
  cosSpread_ = det::cos(s_.spreadDegrees * (det::kPi / 180.0));
  rate_ = EmissionRate(std::llround(s_.rate * static_cast<double>(EmissionRate::kMicrosPerSecond)),
                       s_.start, s_.stop, stepRate_);
  for (const Burst& b : s_.bursts)
    burstTicks_.emplace_back(exact::tickAtOrAfter(b.time, stepRate_), b.count);
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

std::uint64_t Emitter::emit(ParticlePool& pool, std::uint64_t seed, std::int64_t tick,
                            const Shard& shard) const {
  const std::uint64_t first = serialBefore(tick);
  const std::uint64_t last = serialBefore(tick + 1);
  // Serials are counted from tick 0, so a later tick never has made fewer particles.
  TICKFX_ASSERT(first <= last, "an emitter's serials going backwards");
  TICKFX_ASSERT(pool.size() <= pool.maxParticles(), "a pool past its maxParticles");
  // This pool's serials of [first, last): every count-th from the first it owns (all of them for
  // the whole run).
  const std::uint64_t own = shard.firstOwnedSerial(index_, first);
  const std::uint64_t owned = own < last ? (last - 1 - own) / shard.count + 1 : 0;
  // Particles the pool has no room for are counted, not sampled (a shard never lacks room: a cap
  // that may bind is refused before a run is sharded).
  const std::uint64_t tried = std::min<std::uint64_t>(owned, pool.maxParticles() - pool.size());
  TICKFX_ASSERT(shard.whole() || tried == owned, "a shard's pool reaching its cap");
  // Every particle is a pure function of its serial: the rows are reserved in serial order, then
  // filled in parallel blocks, with the bits of one spawn() after another. Ids go to the rows
  // made and to the other shards' particles; refused spawns take none.
  const std::size_t firstRow =
      pool.appendRowsStrided(static_cast<std::size_t>(tried), tick, own - first, shard.count,
                             tried + (last - first - owned));
  TICKFX_ASSERT(firstRow + tried == pool.size(), "an emitter's rows not at the pool's end");
  const SpawnRecipe recipe = spawnRecipe(seed);
  parallelForRows(static_cast<std::size_t>(tried), [&](std::size_t begin, std::size_t end) {
    for (std::size_t k = begin; k < end; k += kSpawnBatchRows) {
      const std::size_t n = std::min(kSpawnBatchRows, end - k);
      spawnRows(recipe, own + k * shard.count, shard.count, n, pool.spawnTargets(firstRow + k));
      pool.finishRows(firstRow + k, firstRow + k + n);
    }
  });
  pool.refuseSpawns(owned - tried);
  return last - first;
}

SpawnRecipe Emitter::spawnRecipe(std::uint64_t seed) const {
  SpawnRecipe r;
  r.emitterKey = emitterKey(seed, index_);
  r.position = s_.position;
  if (const auto* sphere = std::get_if<SphereShape>(&s_.shape)) {
    r.shape = SpawnRecipe::Shape::Sphere;
    r.radius = sphere->radius;
    r.surface = sphere->surface;
  } else if (const auto* box = std::get_if<BoxShape>(&s_.shape)) {
    r.shape = SpawnRecipe::Shape::Box;
    r.boxSize = box->size;
  } else if (const auto* disc = std::get_if<DiscShape>(&s_.shape)) {
    r.shape = SpawnRecipe::Shape::Disc;
    r.radius = disc->radius;
    r.discB1 = discB1_;
    r.discB2 = discB2_;
  } else if (const auto* list = std::get_if<PointListShape>(&s_.shape)) {
    r.shape = SpawnRecipe::Shape::PointList;
    r.points = list->positions;
    r.pointVelocities = list->velocities;
  }
  r.direction = s_.direction;
  r.directionB1 = directionB1_;
  r.directionB2 = directionB2_;
  r.spreadDegrees = s_.spreadDegrees;
  r.cosSpread = cosSpread_;
  r.speed = s_.speed;
  r.speedJitter = s_.speedJitter;
  r.lifetime = s_.lifetime;
  r.lifetimeJitter = s_.lifetimeJitter;
  r.mass = s_.mass;
  return r;
}

void Emitter::sampleBatch(std::uint64_t seed, std::uint64_t firstSerial, std::uint64_t stride,
                          std::span<ParticleInit> out) const {
  spawnBatch(spawnRecipe(seed), firstSerial, stride, out);
}

ParticleInit Emitter::draw(const ParticleRandom& random, const Eigen::Vector3d& direction,
                           const Eigen::Vector3d& b1, const Eigen::Vector3d& b2,
                           Eigen::Vector3d& offset) const {
  const auto uniform = [&](RandomPurpose purpose) {
    return random.uniform(static_cast<std::uint32_t>(purpose));
  };
  constexpr double kTwoPi = 2.0 * det::kPi;

  offset = Eigen::Vector3d::Zero();
  if (const auto* sphere = std::get_if<SphereShape>(&s_.shape)) {
    const double z = 1.0 - 2.0 * uniform(RandomPurpose::PositionU);
    const double rxy = std::sqrt(std::max(0.0, 1.0 - z * z));
    double sinPhi = 0.0, cosPhi = 0.0;
    det::sincos(kTwoPi * uniform(RandomPurpose::PositionV), sinPhi, cosPhi);
    const double r = sphere->surface
                         ? sphere->radius
                         : sphere->radius * det::cbrt(uniform(RandomPurpose::PositionW));
    offset = r * Eigen::Vector3d(rxy * cosPhi, rxy * sinPhi, z);
  } else if (const auto* box = std::get_if<BoxShape>(&s_.shape)) {
    offset = Eigen::Vector3d(uniform(RandomPurpose::PositionU) - 0.5,
                             uniform(RandomPurpose::PositionV) - 0.5,
                             uniform(RandomPurpose::PositionW) - 0.5)
                 .cwiseProduct(box->size);
  } else if (const auto* disc = std::get_if<DiscShape>(&s_.shape)) {
    const double r = disc->radius * std::sqrt(uniform(RandomPurpose::PositionU));
    double sinPhi = 0.0, cosPhi = 0.0;
    det::sincos(kTwoPi * uniform(RandomPurpose::PositionV), sinPhi, cosPhi);
    offset = (r * cosPhi) * discB1_ + (r * sinPhi) * discB2_;
  }

  Eigen::Vector3d dir = direction;
  if (s_.spreadDegrees > 0.0) {
    // Uniform over the spherical cap of half-angle `spread` around the direction.
    const double cosT = 1.0 - uniform(RandomPurpose::DirectionU) * (1.0 - cosSpread_);
    const double sinT = std::sqrt(std::max(0.0, 1.0 - cosT * cosT));
    double sinPhi = 0.0, cosPhi = 0.0;
    det::sincos(kTwoPi * uniform(RandomPurpose::DirectionV), sinPhi, cosPhi);
    dir = (sinT * cosPhi) * b1 + (sinT * sinPhi) * b2 + cosT * direction;
  }
  const double speed =
      s_.speed * (1.0 + s_.speedJitter * (2.0 * uniform(RandomPurpose::Speed) - 1.0));
  const double life =
      s_.lifetime * (1.0 + s_.lifetimeJitter * (2.0 * uniform(RandomPurpose::Lifetime) - 1.0));

  ParticleInit init;
  init.velocity = (speed * dir).cast<float>();
  init.lifetime = static_cast<float>(life);
  init.mass = static_cast<float>(s_.mass);
  return init;
}

ParticleInit Emitter::sample(std::uint64_t seed, std::uint64_t serial) const {
  Eigen::Vector3d offset;
  ParticleInit init =
      draw(ParticleRandom(seed, index_, serial), s_.direction, directionB1_, directionB2_, offset);
  init.position = (s_.position + offset).cast<float>();
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
  return init;
}

namespace {

// The counter of an event and of one of its children, standing for the serial of an emitted
// particle in the random key: bijective mixes, so distinct (parent, ordinal, child) give distinct
// keys but for 64-bit collisions.
std::uint64_t eventKey(const ParticleEvent& event) {
  return mix64(mix64(event.parentId + 0x632be59bd9b4e019ULL) ^
               (static_cast<std::uint64_t>(event.ordinal) * 0x9e3779b97f4a7c15ULL +
                static_cast<std::uint64_t>(event.kind)));
}

std::uint64_t childKey(const ParticleEvent& event, std::uint64_t child) {
  return mix64(eventKey(event) ^ ((child + 1) * 0xd1b54a32d192ed03ULL));
}

}  // namespace

std::uint64_t Emitter::childCount(std::uint64_t seed, const ParticleEvent& event) const {
  const SubEmitterSettings& sub = s_.sub;
  if (sub.firstOnly && event.ordinal > 0) return 0;
  if (sub.countMax <= sub.countMin) return sub.countMin;
  const ParticleRandom random(seed, index_, eventKey(event));
  const std::uint64_t span = sub.countMax - sub.countMin + 1;
  // Lemire's multiply-shift: uniform up to a bias of span / 2^64, exact in integers.
  const auto wide = static_cast<unsigned __int128>(
                        random.bits(static_cast<std::uint32_t>(RandomPurpose::ChildCount))) *
                    span;
  return sub.countMin + static_cast<std::uint64_t>(wide >> 64);
}

ParticleInit Emitter::sampleChild(std::uint64_t seed, const ParticleEvent& event,
                                  std::uint64_t child) const {
  const ParticleRandom random(seed, index_, childKey(event, child));
  Eigen::Vector3d offset;
  ParticleInit init;
  if (s_.sub.alongNormal) {
    Eigen::Vector3d n = event.normal.cast<double>();
    if (!normalisable(n)) n = s_.direction;  // no contact normal: the emitter's direction
    n.normalize();
    Eigen::Vector3d b1, b2;
    basis(n, b1, b2);
    init = draw(random, n, b1, b2, offset);
  } else {
    init = draw(random, s_.direction, directionB1_, directionB2_, offset);
  }
  // In float from the event on (it is float): the offset and the emitted velocity are rounded to
  // float once, then added, so no float value goes through double and back.
  const Eigen::Vector3f shift = (s_.position + offset).cast<float>();
  init.position = shift.isZero(0.0f) ? event.position : Eigen::Vector3f(event.position + shift);
  if (s_.sub.inheritVelocity != 0.0) {
    init.velocity += static_cast<float>(s_.sub.inheritVelocity) * event.velocity;
  }
  return init;
}

}  // namespace tickfx

#include "io/FrameData.h"

#include "particles/ParticleSystem.h"

namespace tickfx::io {

void FrameData::resize(std::size_t rows, std::vector<std::string> names) {
  const auto n = static_cast<Eigen::Index>(rows);
  id.resize(rows);
  position.resize(n);
  velocity.resize(n);
  age.resize(n);
  life.resize(n);
  mass.resize(n);
  attributeNames = std::move(names);
  attributes.assign(attributeNames.size(), FloatColumn(n));
}

FrameData captureFrame(const ParticleSystem& system, std::int64_t frame, double timeSeconds) {
  const ParticlePool& pool = system.pool();
  const auto n = static_cast<Eigen::Index>(pool.size());
  FrameData data;
  data.frame = frame;
  data.timeSeconds = timeSeconds;
  data.id.assign(pool.id().begin(), pool.id().begin() + n);
  system.renderPositions(data.position);
  system.renderVelocities(data.velocity);
  system.renderAges(data.age);
  data.life = pool.lifetime().head(n);
  data.mass = pool.mass().head(n);
  for (std::size_t a = 0; a < pool.attributeCount(); ++a) {
    data.attributeNames.push_back(pool.attributeName(a));
    data.attributes.emplace_back(pool.attribute(a).head(n));
  }
  return data;
}

}  // namespace tickfx::io

#include "io/cache/FrameData.h"

#include <algorithm>

#include "io/util/Fingerprint.h"
#include "particles/ParallelFor.h"
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
  const std::size_t rows = pool.size();
  system.renderPositions(data.position);
  system.renderVelocities(data.velocity);
  system.renderAges(data.age);
  // The stored columns are copied in parallel blocks (a frame of 10^8 rows is 2 GB of them).
  data.id.resize(rows);
  data.life.resize(n);
  data.mass.resize(n);
  parallelForRows(rows, [&](std::size_t b, std::size_t e) {
    std::copy(pool.id().begin() + b, pool.id().begin() + e, data.id.begin() + b);
    std::copy(pool.lifetime().data() + b, pool.lifetime().data() + e, data.life.data() + b);
    std::copy(pool.mass().data() + b, pool.mass().data() + e, data.mass.data() + b);
  });
  // Attributes over life are evaluated here, at the frame's ages: nothing of them is stored.
  const LifeAttributeSet& life = system.lifeAttributes();
  for (std::string& name : system.attributeNames()) {
    const int declared = life.find(name);
    if (declared >= 0) {
      FloatColumn values(n);
      life.evaluate(declared, pool, data.age.data(),
                    FloatDestination{values.data(), sizeof(float), pool.size()});
      data.attributes.push_back(std::move(values));
    } else {
      const FloatColumn& stored = pool.attribute(pool.findAttribute(name));
      FloatColumn values(n);
      parallelForRows(rows, [&](std::size_t b, std::size_t e) {
        std::copy(stored.data() + b, stored.data() + e, values.data() + b);
      });
      data.attributes.push_back(std::move(values));
    }
    data.attributeNames.push_back(std::move(name));
  }
  return data;
}

std::uint64_t frameHash(const FrameData& data) {
  const std::size_t n = data.size();
  std::string bytes;
  auto append = [&](const void* p, std::size_t size) {
    bytes.append(static_cast<const char*>(p), size);
  };
  auto appendFloats = [&](const FloatColumn& c) { append(c.data(), n * sizeof(float)); };
  append(&n, sizeof n);
  append(data.id.data(), n * sizeof(std::uint64_t));
  for (const Vec3Column* v : {&data.position, &data.velocity}) {
    for (int k = 0; k < 3; ++k) appendFloats((*v)[k]);
  }
  for (const FloatColumn* c : {&data.age, &data.life, &data.mass}) appendFloats(*c);
  for (std::size_t a = 0; a < data.attributes.size(); ++a) {
    bytes += data.attributeNames[a] + '\0';
    appendFloats(data.attributes[a]);
  }
  return fingerprint(bytes);
}

}  // namespace tickfx::io

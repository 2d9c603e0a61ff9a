#include "particles/LifeAttributeSet.h"

#include <algorithm>
#include <cmath>

#include "particles/ParallelFor.h"
#include "particles/Random.h"

namespace tickfx {

LifeAttributeSet::LifeAttributeSet(const std::vector<EmitterSettings>& emitters, std::uint64_t seed,
                                   bool sources)
    : seed_(seed) {
  bool subEmitters = false;
  for (const EmitterSettings& e : emitters) {
    subEmitters |= !e.sub.parent.empty();
    lists_.push_back(e.attributes);
  }
  for (std::size_t e = 0; e < lists_.size(); ++e) {
    const std::vector<LifeAttributeSettings>& list = lists_[e];
    for (std::size_t a = 0; a < list.size(); ++a) {
      const std::vector<std::string> names = list[a].columnNames();
      for (std::size_t c = 0; c < names.size(); ++c) {
        int column = find(names[c]);
        if (column < 0) {
          column = static_cast<int>(columns_.size());
          columns_.push_back(names[c]);
          sources_.emplace_back(lists_.size());
        }
        sources_[static_cast<std::size_t>(column)][e] = Source{
            &list[a], static_cast<int>(c),
            static_cast<std::uint32_t>(RandomPurpose::Attribute) + static_cast<std::uint32_t>(a)};
      }
    }
  }
  needsEmitterColumn_ = subEmitters || (!columns_.empty() && (lists_.size() > 1 || sources));
}

int LifeAttributeSet::find(const std::string& column) const {
  const auto it = std::find(columns_.begin(), columns_.end(), column);
  return it == columns_.end() ? -1 : static_cast<int>(it - columns_.begin());
}

const float* LifeAttributeSet::emitterColumn(const ParticlePool& pool) {
  const std::size_t c = pool.findAttribute(kEmitterColumn);
  return c == ParticlePool::npos ? nullptr : pool.attribute(c).data();
}

float LifeAttributeSet::rowValue(int column, int emitter, std::uint64_t id, float age,
                                 float lifetime, float stored) const {
  if (emitter < 0 || static_cast<std::size_t>(emitter) >= lists_.size()) return stored;
  const Source& s = sources_[static_cast<std::size_t>(column)][static_cast<std::size_t>(emitter)];
  if (s.settings == nullptr) return stored;
  float u = 0.0f;
  if (s.settings->kind == LifeAttributeSettings::Kind::Random) {
    u = unitFromBits(
        ParticleRandom(seed_, static_cast<std::uint32_t>(emitter), id).bits(s.purpose));
  }
  return s.settings->evaluate(s.component, normalisedAge(age, lifetime), u);
}

void LifeAttributeSet::evaluate(int column, const ParticlePool& pool, const float* ages,
                                const FloatDestination& out) const {
  const std::string& name = columns_[static_cast<std::size_t>(column)];
  const std::size_t storedColumn = pool.findAttribute(name);
  const float* stored =
      storedColumn == ParticlePool::npos ? nullptr : pool.attribute(storedColumn).data();
  const float fallback = LifeAttributeSettings::defaultValue(name);
  const float* emitters = emitterColumn(pool);
  const float* life = pool.lifetime().data();
  const std::uint64_t* ids = pool.id().data();
  parallelForRows(pool.size(), [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) {
      *reinterpret_cast<float*>(reinterpret_cast<char*>(out.data) + i * out.rowStride) =
          rowValue(column, emitterOf(emitters, i), ids[i], ages[i], life[i],
                   stored != nullptr ? stored[i] : fallback);
    }
  });
}

}  // namespace tickfx

// The attributes over life of every emitter of a system, evaluated when a frame is shown.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "particles/Emitter.h"
#include "particles/ParticlePool.h"
#include "particles/RenderDestination.h"

namespace tickfx {

/// The name of the pool column that says which emitter made a row (a whole number: the emitter's
/// index in the effect, −1 for a structure's particles). A pool has it only when rows must be
/// told apart: sub-emitters, or attributes over life with more than one source of particles.
inline constexpr const char* kEmitterColumn = "emitter";

/// Evaluates the attributes declared by emitters (EmitterSettings::attributes) for the rows of a
/// pool. Nothing here runs in a tick: the values are pure functions of (the emitter, the
/// particle's id, its age and lifetime), the random ones keyed by (seed, emitter, id, purpose)
/// (the id, unlike a serial, is what every particle, a sub-emitter's child too, has). A column
/// the pool also holds (an attribute children inherit) gives the stored value for the rows of
/// emitters that do not declare it; a row whose emitter neither declares nor stores it shows
/// LifeAttributeSettings::defaultValue().
class LifeAttributeSet {
 public:
  LifeAttributeSet() = default;
  /// `sources`: the effect has other particles than the emitters' (structures).
  LifeAttributeSet(const std::vector<EmitterSettings>& emitters, std::uint64_t seed, bool sources);
  // Sources point into lists_: moving keeps the heap blocks they point into, copying would not.
  LifeAttributeSet(const LifeAttributeSet&) = delete;
  LifeAttributeSet& operator=(const LifeAttributeSet&) = delete;
  LifeAttributeSet(LifeAttributeSet&&) noexcept = default;
  LifeAttributeSet& operator=(LifeAttributeSet&&) noexcept = default;

  bool empty() const { return columns_.empty(); }
  /// Whether rows need kEmitterColumn to find their emitter's attributes.
  bool needsEmitterColumn() const { return needsEmitterColumn_; }
  /// The declared columns ("Cd_r", "Cd_g", "Cd_b", "Alpha", "pscale", custom), in order of first
  /// declaration.
  const std::vector<std::string>& columns() const { return columns_; }
  /// Index of `column` in columns(), or −1.
  int find(const std::string& column) const;

  /// `column` (an index of columns()) of rows [0, pool.size()), at the shown ages `ages` (one per
  /// row), into `out` (its capacity at least pool.size()). Parallel over rows; the bits do not
  /// depend on the thread count.
  void evaluate(int column, const ParticlePool& pool, const float* ages,
                const FloatDestination& out) const;
  /// One particle's value of `column`: that of its emitter's declaration (emitter −1: none), else
  /// `stored` (its pool column's value, or defaultValue() where the pool has none). For a frame's
  /// rows (evaluate()) and for what children inherit at an event.
  float rowValue(int column, int emitter, std::uint64_t id, float age, float lifetime,
                 float stored) const;

  /// kEmitterColumn's values in `pool`, or null when it has none (every row is then emitter 0).
  static const float* emitterColumn(const ParticlePool& pool);
  /// Which emitter made row `row` (−1: none) by emitterColumn()'s values.
  static int emitterOf(const float* emitters, std::size_t row) {
    return emitters != nullptr ? static_cast<int>(emitters[row]) : 0;
  }

 private:
  struct Source {
    const LifeAttributeSettings* settings = nullptr;  // null: not declared by this emitter
    int component = 0;
    std::uint32_t purpose = 0;  // the random draw's purpose
  };
  std::vector<std::vector<LifeAttributeSettings>> lists_;  // per emitter; sources point in
  std::uint64_t seed_ = 0;
  bool needsEmitterColumn_ = false;
  std::vector<std::string> columns_;
  std::vector<std::vector<Source>> sources_;  // [column][emitter]
};

}  // namespace tickfx

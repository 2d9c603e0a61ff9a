// Runs the dispatching loops (particles/Isa.h) on each path this processor has, so that a test
// pins every path to its reference bit for bit.
#pragma once

#include <optional>
#include <vector>

#include "particles/Isa.h"

namespace tickfx::test {

/// Baseline, then every wider path available here.
inline std::vector<Isa> isasHere() {
  std::vector<Isa> out{Isa::Baseline};
  if (isaAvailable(Isa::Avx2)) out.push_back(Isa::Avx2);
  return out;
}

/// forceIsa(isa) while alive; the default (the widest) again after.
struct ForcedIsa {
  explicit ForcedIsa(Isa isa) { forceIsa(isa); }
  ~ForcedIsa() { forceIsa(std::nullopt); }
  ForcedIsa(const ForcedIsa&) = delete;
  ForcedIsa& operator=(const ForcedIsa&) = delete;
};

}  // namespace tickfx::test

// The paths of the dispatching loops (particles/Isa.h) this processor has, so that a test pins
// every path to its reference bit for bit (under a tickfx::ForcedIsa).
#pragma once

#include <vector>

#include "particles/Isa.h"

namespace tickfx::test {

/// Baseline, then every wider path available here.
inline std::vector<Isa> isasHere() {
  std::vector<Isa> out{Isa::Baseline};
  if (isaAvailable(Isa::Avx2)) out.push_back(Isa::Avx2);
  if (isaAvailable(Isa::Avx512)) out.push_back(Isa::Avx512);
  return out;
}

}  // namespace tickfx::test

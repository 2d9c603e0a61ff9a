#include "particles/Isa.h"

#include <atomic>

#include "particles/Assert.h"

namespace tickfx {
namespace {

// The widest Isa this processor runs. __builtin_cpu_supports() reports AVX and AVX-512 only where
// the system also saves their registers (XGETBV), as libgcc and compiler-rt read them.
Isa widestHere() {
#ifdef TICKFX_AVX2_CLONES
  static const Isa widest = [] {
    __builtin_cpu_init();
    if (__builtin_cpu_supports("avx2") == 0) return Isa::Baseline;
    // The AVX-512 clones are compiled for F, and the sampler's also for DQ (vpmullq) and VL:
    // all three, or none is taken (Knights Landing has F without DQ and VL).
    const bool avx512 = __builtin_cpu_supports("avx512f") != 0 &&
                        __builtin_cpu_supports("avx512dq") != 0 &&
                        __builtin_cpu_supports("avx512vl") != 0;
    return avx512 ? Isa::Avx512 : Isa::Avx2;
  }();
  return widest;
#else
  return Isa::Baseline;
#endif
}

// -1: the widest path available; else a forced Isa (forceIsa()).
std::atomic<int> forced{-1};

}  // namespace

bool isaAvailable(Isa isa) { return isa <= widestHere(); }

Isa activeIsa() {
  const int f = forced.load(std::memory_order_relaxed);
  if (f >= 0) return static_cast<Isa>(f);
  return widestHere();
}

void forceIsa(std::optional<Isa> isa) {
  TICKFX_ASSERT(!isa || isaAvailable(*isa), "forcing an Isa this processor lacks");
  forced.store(isa ? static_cast<int>(*isa) : -1, std::memory_order_relaxed);
}

const char* isaName(Isa isa) {
  switch (isa) {
    case Isa::Avx2:
      return "AVX2";
    case Isa::Avx512:
      return "AVX-512";
    case Isa::Baseline:
      break;
  }
  return "baseline";
}

}  // namespace tickfx

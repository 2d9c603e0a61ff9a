#include "particles/Isa.h"

#include <atomic>

#include "particles/Assert.h"

namespace tickfx {
namespace {

bool avx2Here() {
#ifdef TICKFX_AVX2_CLONES
  static const bool has = [] {
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx2") != 0;
  }();
  return has;
#else
  return false;
#endif
}

// -1: the widest path available; else a forced Isa (forceIsa()).
std::atomic<int> forced{-1};

}  // namespace

bool isaAvailable(Isa isa) { return isa == Isa::Baseline || avx2Here(); }

Isa activeIsa() {
  const int f = forced.load(std::memory_order_relaxed);
  if (f >= 0) return static_cast<Isa>(f);
  return avx2Here() ? Isa::Avx2 : Isa::Baseline;
}

void forceIsa(std::optional<Isa> isa) {
  TICKFX_ASSERT(!isa || isaAvailable(*isa), "forcing an Isa this processor lacks");
  forced.store(isa ? static_cast<int>(*isa) : -1, std::memory_order_relaxed);
}

const char* isaName(Isa isa) { return isa == Isa::Avx2 ? "AVX2" : "baseline"; }

}  // namespace tickfx

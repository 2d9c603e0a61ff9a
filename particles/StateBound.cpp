#include "particles/StateBound.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>

#include "particles/Isa.h"

namespace tickfx {
namespace {

using Bits4 = std::int32_t __attribute__((vector_size(16)));
using Bits8 = std::int32_t __attribute__((vector_size(32)));
using Bits16 = std::int32_t __attribute__((vector_size(64)));

// magnitudeBits() a register of Bits at a time: a max in integer lanes (a float max the compiler
// does not vectorise without -ffast-math), in four independent chains so that the loop is bound
// by its loads, not by one chain of compares (a fused frame runs it over each block's rows in
// cache, where one chain took a third of the frame at 10⁷ rows).
template <class Bits>
[[gnu::always_inline]] inline std::uint32_t largestMagnitude(const float* column, std::size_t begin,
                                                             std::size_t end) {
  constexpr std::size_t w = sizeof(Bits) / sizeof(std::int32_t);
  Bits most[4] = {};
  std::size_t i = begin;
  for (; i + 4 * w <= end; i += 4 * w) {
    for (std::size_t k = 0; k < 4; ++k) {
      Bits value;
      std::memcpy(&value, column + i + k * w, sizeof value);
      value &= 0x7fffffff;
      most[k] = value > most[k] ? value : most[k];
    }
  }
  std::int32_t largest = 0;
  for (const Bits& m : most) {
    for (std::size_t lane = 0; lane < w; ++lane) largest = std::max(largest, m[lane]);
  }
  for (; i < end; ++i) {
    largest = std::max(largest, std::bit_cast<std::int32_t>(column[i]) & 0x7fffffff);
  }
  return static_cast<std::uint32_t>(largest);
}

#ifdef TICKFX_AVX2_CLONES
[[gnu::target("avx2"), gnu::flatten]] std::uint32_t largestAvx2(const float* column,
                                                                std::size_t begin,
                                                                std::size_t end) {
  return largestMagnitude<Bits8>(column, begin, end);
}
[[gnu::target("avx2,avx512f"), gnu::flatten]] std::uint32_t largestAvx512(const float* column,
                                                                          std::size_t begin,
                                                                          std::size_t end) {
  return largestMagnitude<Bits16>(column, begin, end);
}
#endif

}  // namespace

std::uint32_t magnitudeBits(const float* column, std::size_t begin, std::size_t end) {
#ifdef TICKFX_AVX2_CLONES
  switch (activeIsa()) {
    case Isa::Avx512:
      return largestAvx512(column, begin, end);
    case Isa::Avx2:
      return largestAvx2(column, begin, end);
    case Isa::Baseline:
      break;
  }
#endif
  return largestMagnitude<Bits4>(column, begin, end);
}

double boundOfBits(std::uint32_t bits) {
  const std::uint32_t magnitude = bits & 0x7fffffffU;
  return magnitude >= 0x7f800000U ? INFINITY : static_cast<double>(std::bit_cast<float>(magnitude));
}

void LargestMagnitudes::add(const ParticlePool& pool, const Vec3Column* extra, std::size_t begin,
                            std::size_t end) {
  const Vec3Column* state[3] = {&pool.position(), &pool.velocity(), extra};
  for (int s = 0; s < 3; ++s) {
    if (state[s] == nullptr) continue;
    std::uint32_t largest = 0;
    for (int c = 0; c < 3; ++c)
      largest = std::max(largest, magnitudeBits((*state[s])[c].data(), begin, end));
    std::uint32_t seen = bits_[s].load(std::memory_order_relaxed);
    while (largest > seen && !bits_[s].compare_exchange_weak(seen, largest)) {
    }
  }
}

StateBound LargestMagnitudes::bound() const {
  return {boundOfBits(bits_[0].load()), boundOfBits(bits_[1].load()), boundOfBits(bits_[2].load())};
}

}  // namespace tickfx

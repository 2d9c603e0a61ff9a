// Deterministic maths and counter-based random numbers.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <vector>

#include "particles/DetMath.h"
#include "particles/Random.h"

namespace tickfx {
namespace {

double ulpOf(double x) {
  const double a = std::abs(x);
  return std::nextafter(a, std::numeric_limits<double>::infinity()) - a;
}

TEST(DetMath, SinAndCosAgreeWithTheLibmOnADenseGrid) {
  double worstSin = 0.0, worstCos = 0.0;
  for (int i = -400'000; i <= 400'000; ++i) {
    const double x = i * 2.5e-4;  // [−100, 100]
    worstSin = std::max(worstSin, std::abs(det::sin(x) - std::sin(x)));
    worstCos = std::max(worstCos, std::abs(det::cos(x) - std::cos(x)));
  }
  // Measured: 1.1e-16 for both (half an ulp of values near 1).
  EXPECT_LE(worstSin, 1e-15);
  EXPECT_LE(worstCos, 1e-15);
}

TEST(DetMath, ExactValuesAndNonFiniteInputs) {
  EXPECT_EQ(det::sin(0.0), 0.0);
  EXPECT_EQ(det::cos(0.0), 1.0);
  EXPECT_NEAR(det::sin(det::kPi / 2.0), 1.0, 1e-16);
  EXPECT_NEAR(det::cos(det::kPi), -1.0, 1e-16);
  EXPECT_TRUE(std::isnan(det::sin(std::numeric_limits<double>::infinity())));
  EXPECT_TRUE(std::isnan(det::cos(std::numeric_limits<double>::quiet_NaN())));
}

// The header promises a few ulps for |x| < 1e5, which matters most near the zeros, where the
// result is small and the range reduction must keep π/2 to about 2^-120. sin(k·π) for the double
// nearest k·π is k·π's rounding error, ~1.2e-16·k; glibc's sin is within an ulp of it.
TEST(DetMath, SinAndCosStayAccurateNearTheirZeros) {
  for (double k : {1.0, 2.0, 3.0, 7.0, 10.0, 31.0, 100.0, 1000.0, 10000.0, 31830.0}) {
    const double x = k * det::kPi;
    EXPECT_NEAR(det::sin(x), std::sin(x), 4.0 * ulpOf(std::sin(x))) << "sin(" << k << "π)";
    const double y = (k + 0.5) * det::kPi;
    EXPECT_NEAR(det::cos(y), std::cos(y), 4.0 * ulpOf(std::cos(y))) << "cos(" << k + 0.5 << "π)";
  }
}

// Regression (issue 10, item 14): past about 1e5 the reduction lost its precision and past ~1e15
// the result left [−1, 1] (curl noise at 1e9 rad/m over 1e8 m stored |u| ≈ 9e5); past ~1.4e19
// the quadrant's cast to int64 was undefined. Now the reduction is exact for every double:
// checked against long double (glibc reduces sinl exactly) from 2^19 to 1e300.
TEST(DetMath, SinAndCosAreAccurateForEveryFiniteArgument) {
  std::vector<double> xs;
  for (double x = 524288.0; x < 1e300; x *= 1.37) xs.push_back(x);
  for (int e = 19; e < 1024; e += 7) xs.push_back(std::ldexp(1.0, e));
  for (double k : {1e6, 3.0e8, 7.7e12, 1e17, 1e22}) {
    xs.push_back(k * det::kPi / 2.0);  // near a multiple of π/2: a tiny remainder
    xs.push_back(std::nextafter(k * det::kPi, 0.0));
  }
  xs.push_back(std::numeric_limits<double>::max());
  xs.push_back(6381956970095103.0 * std::ldexp(1.0, 797));  // the double nearest a multiple of π/2
  int checked = 0;
  for (double x : xs) {
    for (double sx : {x, -x}) {
      const long double s = sinl(static_cast<long double>(sx));
      const long double c = cosl(static_cast<long double>(sx));
      ASSERT_LE(std::fabs(det::sin(sx)), 1.0) << sx;
      ASSERT_LE(std::fabs(det::cos(sx)), 1.0) << sx;
      ASSERT_NEAR(det::sin(sx), static_cast<double>(s), 5e-14) << sx;
      ASSERT_NEAR(det::cos(sx), static_cast<double>(c), 5e-14) << sx;
      ++checked;
    }
  }
  EXPECT_GT(checked, 2000);
}

// Below 2^19 the reduction is the Cody–Waite one it always was: the same bits as before (the
// golden hashes of the wind and of the emitters' directions depend on them).
TEST(DetMath, SmallArgumentsKeepTheirBits) {
  std::uint64_t h = 0xcbf29ce484222325ULL;
  for (int i = -20000; i <= 20000; ++i) {
    const double x = i * 26.2143;  // to ±524286
    for (double v : {det::sin(x), det::cos(x)}) {
      std::uint64_t bits = 0;
      std::memcpy(&bits, &v, sizeof bits);
      h = (h ^ bits) * 0x100000001b3ULL;
    }
  }
  EXPECT_EQ(h, 0xe57d4ee2f35d3009ULL) << std::hex << h;  // the value before the change
}

TEST(DetMath, CbrtCubesBackToItsArgument) {
  double worst = 0.0;
  for (int e = -1000; e <= 1000; e += 7) {
    for (double m : {1.0, 1.1, 1.37, 1.5, 1.77, 1.999}) {
      const double x = std::ldexp(m, e);
      const double c = det::cbrt(x);
      // c within an ulp of the root (≤ 2^-52 relative) triples in c³, plus two roundings of the
      // product: |c³ − x| ≤ 8·2^-53·x = 8.9e-16·x. Measured: 6.5e-16·x.
      worst = std::max(worst, std::abs(c * c * c - x) / x);
      ASSERT_NEAR(c, static_cast<double>(cbrtl(static_cast<long double>(x))), ulpOf(c)) << x;
    }
  }
  EXPECT_LE(worst, 8.0 * 0x1p-53);
  EXPECT_EQ(det::cbrt(27.0), 3.0);
  EXPECT_EQ(det::cbrt(0.125), 0.5);
  EXPECT_EQ(det::cbrt(1.0), 1.0);
  EXPECT_EQ(det::cbrt(0.0), 0.0);
  EXPECT_TRUE(std::isnan(det::cbrt(-1.0)));
}

// The emitter feeds it uniform numbers in [2^-53, 1): all of them must come back within an ulp.
TEST(DetMath, CbrtOfUniformNumbers) {
  for (std::uint64_t serial = 0; serial < 20000; ++serial) {
    const double u = randomUniform(RandomKey{3, 0, serial, 3});
    if (u == 0.0) continue;
    const double c = det::cbrt(u);
    ASSERT_NEAR(c, static_cast<double>(cbrtl(static_cast<long double>(u))), ulpOf(c)) << u;
  }
}

// The Newton iteration as it was written first: every step until a fixed point or 60 of them.
// det::cbrt stops early on a two-value cycle; its bits must be this loop's, cycles included.
double cbrtAllSteps(double x) {
  int e = 0;
  const double m = std::frexp(x, &e);
  double y = std::ldexp(1.0, e >= 0 ? e / 3 : -((-e) / 3));
  y = y * (m > 0.75 ? 1.0 : 0.8);
  for (int i = 0; i < 60; ++i) {
    const double next = y - (y * y * y - x) / (3.0 * y * y);
    if (next == y) break;
    y = next;
  }
  return y;
}

TEST(DetMath, CbrtGivesTheBitsOfEverySixtyStepsIncludingCycles) {
  int cycles = 0;
  for (std::uint64_t serial = 0; serial < 200000; ++serial) {
    const std::uint64_t bits = randomBits(RandomKey{5, 1, serial, 9});
    // Half uniform numbers in (0, 1), half any positive finite double.
    double x = serial % 2 == 0 ? uniformFromBits(bits) : std::bit_cast<double>(bits >> 1);
    if (!(x > 0.0) || !std::isfinite(x)) continue;
    const double all = cbrtAllSteps(x);
    ASSERT_EQ(std::bit_cast<std::uint64_t>(det::cbrt(x)), std::bit_cast<std::uint64_t>(all)) << x;
    double y = all;
    cycles += y - (y * y * y - x) / (3.0 * y * y) != y;  // still moving after 60 steps: a cycle
  }
  EXPECT_GT(cycles, 1000);  // about one input in 15: the cycle path is exercised
}

// sincos is sin and cos from one reduction: the same bits in every quadrant, for small, large
// (Payne–Hanek) and negative arguments.
TEST(DetMath, SincosGivesTheBitsOfSinAndCos) {
  std::vector<double> xs{0.0,      -0.0, 1e-300, det::kPi / 4, det::kPi / 2,
                         det::kPi, 1e6,  -1e6,   1e22,         -3e300};
  for (int k = -2000; k <= 2000; ++k) xs.push_back(k * 0.0123456789);
  for (std::uint64_t serial = 0; serial < 2000; ++serial)
    xs.push_back(2.0 * det::kPi * randomUniform(RandomKey{1, 0, serial, 5}));
  for (const double x : xs) {
    double s = 0.0, c = 0.0;
    det::sincos(x, s, c);
    ASSERT_EQ(std::bit_cast<std::uint64_t>(s), std::bit_cast<std::uint64_t>(det::sin(x))) << x;
    ASSERT_EQ(std::bit_cast<std::uint64_t>(c), std::bit_cast<std::uint64_t>(det::cos(x))) << x;
  }
  double s = 0.0, c = 0.0;
  det::sincos(std::numeric_limits<double>::infinity(), s, c);
  EXPECT_TRUE(std::isnan(s) && std::isnan(c));
}

// uniformFromBits() builds the double from bit fields (for the batch loops' vector units): it is
// the 53-bit integer's value times 2^-53, bit for bit, on every bit pattern tried.
TEST(Random, UniformFromBitsIsTheTop53BitsTimesTwoToTheMinus53) {
  const auto cast = [](std::uint64_t bits) {
    return static_cast<double>(bits >> 11) * 0x1.0p-53;  // exact: 53 bits, a power of two
  };
  std::vector<std::uint64_t> patterns = {0,
                                         0x7ff,
                                         0x800,
                                         0xfff,
                                         0x1000,
                                         0x1800,
                                         ~0ULL,
                                         ~0ULL - 0x800,
                                         1ULL << 63,
                                         (1ULL << 63) | 0x800,
                                         0x5555555555555555ULL,
                                         0xaaaaaaaaaaaaaaaaULL};
  for (int bit = 0; bit < 64; ++bit) patterns.push_back(1ULL << bit);
  for (std::uint64_t serial = 0; serial < 100'000; ++serial)
    patterns.push_back(randomBits(RandomKey{7, 1, serial, 2}));
  for (const std::uint64_t bits : patterns) {
    ASSERT_EQ(std::bit_cast<std::uint64_t>(uniformFromBits(bits)),
              std::bit_cast<std::uint64_t>(cast(bits)))
        << std::hex << bits;
  }
}

TEST(Random, UniformIsInTheHalfOpenUnitIntervalWithMeanOneHalf) {
  EXPECT_EQ(uniformFromBits(0), 0.0);
  EXPECT_LT(uniformFromBits(~std::uint64_t{0}), 1.0);
  EXPECT_EQ(uniformFromBits(~std::uint64_t{0}), 1.0 - 0x1p-53);
  constexpr int kN = 100'000;
  for (std::uint32_t purpose : {1u, 6u, 64u}) {
    double sum = 0.0, sumSquares = 0.0;
    int bins[10] = {};
    for (std::uint64_t serial = 0; serial < kN; ++serial) {
      const double u = randomUniform(RandomKey{2024, 3, serial, purpose});
      ASSERT_GE(u, 0.0);
      ASSERT_LT(u, 1.0);
      sum += u;
      sumSquares += u * u;
      ++bins[static_cast<int>(u * 10.0)];
    }
    const double mean = sum / kN;
    // σ of the mean: (1/√12)/√N = 9.1e-4; 5σ.
    EXPECT_NEAR(mean, 0.5, 4.6e-3) << "purpose " << purpose;
    EXPECT_NEAR(sumSquares / kN - mean * mean, 1.0 / 12.0, 2e-3) << "purpose " << purpose;
    // Each tenth holds N/10 = 10⁴ ± 95 (1σ); 5σ.
    for (int b = 0; b < 10; ++b) EXPECT_NEAR(bins[b], kN / 10, 475) << "bin " << b;
  }
}

TEST(Random, BitsArePureAndEveryCoordinateMatters) {
  const RandomKey key{7, 2, 1000, 4};
  EXPECT_EQ(randomBits(key), randomBits(RandomKey{7, 2, 1000, 4}));
  EXPECT_NE(randomBits(key), randomBits(RandomKey{8, 2, 1000, 4}));
  EXPECT_NE(randomBits(key), randomBits(RandomKey{7, 3, 1000, 4}));
  EXPECT_NE(randomBits(key), randomBits(RandomKey{7, 2, 1001, 4}));
  EXPECT_NE(randomBits(key), randomBits(RandomKey{7, 2, 1000, 5}));
  // Neighbouring serials give unrelated words: half the bits differ on average (σ of one popcount
  // is 4, of the mean over 10⁴ pairs 0.04; 5σ).
  double flipped = 0.0;
  for (std::uint64_t serial = 0; serial < 10'000; ++serial) {
    flipped += std::popcount(randomBits(RandomKey{1, 0, serial, 1}) ^
                             randomBits(RandomKey{1, 0, serial + 1, 1}));
  }
  EXPECT_NEAR(flipped / 10'000, 32.0, 0.2);
}

// Regression guard: randomBits is part of every effect's look (a seed names the same fountain in
// every version), so its words for known keys are pinned. Any change to a constant or a mixing
// round moves them.
TEST(Random, KnownKeysKeepTheirBitsAcrossVersions) {
  EXPECT_EQ(randomBits(RandomKey{0, 0, 0, 0}), 0xf55beca798195c6full);
  EXPECT_EQ(randomBits(RandomKey{7, 2, 1000, 4}), 0x80f5f13cd31e74e0ull);
  EXPECT_EQ(randomBits(RandomKey{~0ull, ~0u, ~0ull, ~0u}), 0xf7578c44c5683a89ull);
}

// randomBits as first written, a round per coordinate in turn (the pinned words below hold it).
std::uint64_t bitsAsFirstWritten(const RandomKey& key) {
  std::uint64_t h = splitmix64(key.seed);
  h = mix64(h ^ (static_cast<std::uint64_t>(key.emitter) * 0xd1b54a32d192ed03ULL + 1));
  h = mix64(h ^ (key.serial * 0xaef17502108ef2d9ULL + 2));
  return mix64(h ^ (static_cast<std::uint64_t>(key.purpose) * 0xf1357aea2e62a9c5ULL + 3));
}

// ParticleRandom mixes (seed, emitter, serial) once for all of a particle's draws: the values of
// the four rounds, and of randomBits and randomUniform, for every purpose.
TEST(Random, AParticlesDrawsAreTheKeysValues) {
  for (const std::uint64_t seed : {0ull, 7ull, ~0ull}) {
    for (const std::uint32_t emitter : {0u, 3u, ~0u}) {
      for (std::uint64_t serial = 0; serial < 300; ++serial) {
        const ParticleRandom random(seed, emitter, serial * 0x9e3779b9ull);
        for (const std::uint32_t purpose : {0u, 1u, 7u, 64u, ~0u}) {
          const RandomKey key{seed, emitter, serial * 0x9e3779b9ull, purpose};
          ASSERT_EQ(random.bits(purpose), bitsAsFirstWritten(key));
          ASSERT_EQ(randomBits(key), bitsAsFirstWritten(key));
          ASSERT_EQ(std::bit_cast<std::uint64_t>(random.uniform(purpose)),
                    std::bit_cast<std::uint64_t>(uniformFromBits(bitsAsFirstWritten(key))));
          ASSERT_EQ(std::bit_cast<std::uint64_t>(randomUniform(key)),
                    std::bit_cast<std::uint64_t>(uniformFromBits(bitsAsFirstWritten(key))));
        }
      }
    }
  }
}

}  // namespace
}  // namespace tickfx

// The block forms of the deterministic maths (particles/DetMathBlock.h): element by element the
// bits of det::sincos, det::cbrt and std::sqrt(std::max(0.0, x)), for any length and alignment.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "particles/DetMath.h"
#include "particles/DetMathBlock.h"
#include "particles/Random.h"

namespace tickfx {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

std::uint64_t bits(double x) { return std::bit_cast<std::uint64_t>(x); }

// Values where the reductions and the Newton iteration have their edges: signed zeros,
// subnormals, the Cody–Waite limit 2^19 and its neighbours, multiples of π/4 (quadrant
// boundaries, ties of the rounding), huge, infinite and nan arguments.
std::vector<double> edgeValues() {
  std::vector<double> xs{0.0,
                         -0.0,
                         0x1p-1074,
                         -0x1p-1074,
                         0x1p-1022,
                         std::nextafter(0x1p-1022, 0.0),
                         0x1p-53,
                         1.0 - 0x1p-53,
                         0.5,
                         0.75,
                         std::nextafter(0.75, 1.0),
                         1.0,
                         27.0,
                         0.125,
                         524288.0,
                         -524288.0,
                         std::nextafter(524288.0, 0.0),
                         std::nextafter(-524288.0, 0.0),
                         1e22,
                         -3e300,
                         std::numeric_limits<double>::max(),
                         kInf,
                         -kInf,
                         std::nan("")};
  for (int k = -64; k <= 64; ++k) {
    const double x = k * (det::kPi / 4);
    xs.push_back(x);
    xs.push_back(std::nextafter(x, kInf));
    xs.push_back(std::nextafter(x, -kInf));
  }
  return xs;
}

// Random arguments of every kind: uniform numbers in [0, 1) (the emitter's), angles in [0, 2π),
// and any double from random bits (all signs, exponents, nan and inf included).
std::vector<double> randomValues(std::size_t count) {
  std::vector<double> xs;
  for (std::uint64_t serial = 0; serial < count; ++serial) {
    const std::uint64_t b = randomBits(RandomKey{17, 2, serial, 11});
    switch (serial % 4) {
      case 0:
        xs.push_back(uniformFromBits(b));
        break;
      case 1:
        xs.push_back(2.0 * det::kPi * uniformFromBits(b));
        break;
      case 2:
        xs.push_back(std::bit_cast<double>(b >> 1));  // positive, any exponent
        break;
      default:
        xs.push_back(std::bit_cast<double>(b));
        break;
    }
  }
  return xs;
}

std::vector<double> allValues() {
  std::vector<double> xs = edgeValues();
  const std::vector<double> r = randomValues(200'000);
  xs.insert(xs.end(), r.begin(), r.end());
  return xs;
}

TEST(DetMathBlock, SincosBlockGivesTheBitsOfSincos) {
  const std::vector<double> xs = allValues();
  std::vector<double> s(xs.size()), c(xs.size());
  det::sincosBlock(xs.data(), s.data(), c.data(), xs.size());
  int outsideVectorRange = 0;
  for (std::size_t i = 0; i < xs.size(); ++i) {
    double ws = 0.0, wc = 0.0;
    det::sincos(xs[i], ws, wc);
    ASSERT_EQ(bits(s[i]), bits(ws)) << "sine of " << xs[i];
    ASSERT_EQ(bits(c[i]), bits(wc)) << "cosine of " << xs[i];
    outsideVectorRange += !(std::abs(xs[i]) < 524288.0);
  }
  EXPECT_GT(outsideVectorRange, 1000);  // the scalar fallback is exercised too
  // A few values that any change of the kernels or the quadrant choice would move.
  double one[1] = {det::kPi / 2}, sine[1], cosine[1];
  det::sincosBlock(one, sine, cosine, 1);
  EXPECT_EQ(sine[0], 1.0);
  EXPECT_LT(std::abs(cosine[0]), 1e-16);
}

// Any length and any start (unaligned for 16-byte vectors): the loops' tails and their first
// elements.
TEST(DetMathBlock, EveryLengthAndOffsetGivesTheSameBits) {
  const std::vector<double> xs = randomValues(300);
  for (std::size_t offset : {0u, 1u, 3u}) {
    for (std::size_t n = 0; n + offset <= 160; n += (n < 40 ? 1 : 17)) {
      std::vector<double> s(n), c(n), root(n), sq(xs.begin() + offset, xs.begin() + offset + n);
      det::sincosBlock(xs.data() + offset, s.data(), c.data(), n);
      det::cbrtBlock(xs.data() + offset, root.data(), n);
      det::sqrtClampedBlock(sq.data(), n);
      for (std::size_t i = 0; i < n; ++i) {
        const double x = xs[offset + i];
        double ws = 0.0, wc = 0.0;
        det::sincos(x, ws, wc);
        ASSERT_EQ(bits(s[i]), bits(ws)) << x << ", n = " << n;
        ASSERT_EQ(bits(c[i]), bits(wc)) << x << ", n = " << n;
        ASSERT_EQ(bits(root[i]), bits(det::cbrt(x))) << x << ", n = " << n;
        ASSERT_EQ(bits(sq[i]), bits(std::sqrt(std::max(0.0, x)))) << x << ", n = " << n;
      }
    }
  }
}

// The Newton iteration of det::cbrt, all lanes of a group stepping together: each lane keeps the
// root of the step where det::cbrt stops, fixed points and two-value cycles alike.
TEST(DetMathBlock, CbrtBlockGivesTheBitsOfCbrtCyclesIncluded) {
  const std::vector<double> xs = allValues();
  std::vector<double> root(xs.size());
  det::cbrtBlock(xs.data(), root.data(), xs.size());
  int cycles = 0;
  for (std::size_t i = 0; i < xs.size(); ++i) {
    const double want = det::cbrt(xs[i]);
    ASSERT_EQ(bits(root[i]), bits(want)) << "cube root of " << xs[i];
    const double y = want;
    if (xs[i] > 0.0 && std::isfinite(xs[i]))
      cycles += y - (y * y * y - xs[i]) / (3.0 * y * y) != y;  // still moving: a cycle
  }
  EXPECT_GT(cycles, 1000);  // the cycle path, about one input in 15
  double x[3] = {27.0, 0.125, -1.0}, r[3];
  det::cbrtBlock(x, r, 3);
  EXPECT_EQ(r[0], 3.0);
  EXPECT_EQ(r[1], 0.5);
  EXPECT_TRUE(std::isnan(r[2]));
}

TEST(DetMathBlock, SqrtClampedBlockIsTheSquareRootOfTheClampedValue) {
  std::vector<double> xs = allValues();
  std::vector<double> got = xs;
  det::sqrtClampedBlock(got.data(), got.size());
  for (std::size_t i = 0; i < xs.size(); ++i)
    ASSERT_EQ(bits(got[i]), bits(std::sqrt(std::max(0.0, xs[i])))) << xs[i];
  double special[5] = {-1.0, -0.0, std::nan(""), 4.0, 2.0};
  det::sqrtClampedBlock(special, 5);
  EXPECT_EQ(bits(special[0]), bits(0.0));
  EXPECT_EQ(bits(special[1]), bits(0.0));  // +0, as std::max(0.0, −0.0) gives
  EXPECT_EQ(bits(special[2]), bits(0.0));  // std::max(0.0, nan) is 0
  EXPECT_EQ(special[3], 2.0);
  EXPECT_EQ(special[4], std::sqrt(2.0));
}

}  // namespace
}  // namespace tickfx

// Attributes over life against closed forms: ramps at their keys and between them for each
// interpolation, random ranges as pure functions of (seed, emitter, id), and no cost in a tick.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <vector>

#include "CoreTestSupport.h"
#include "particles/LifeAttributeSet.h"
#include "particles/ParticleSystem.h"
#include "particles/Random.h"
#include "particles/StateHash.h"

namespace tickfx {
namespace {

LifeAttributeSettings ramp(RampInterpolation interpolation) {
  LifeAttributeSettings a;
  a.name = "heat";
  a.kind = LifeAttributeSettings::Kind::Ramp;
  a.keys = {RampKey{0.0f, {10.0f}}, RampKey{0.5f, {20.0f}}, RampKey{0.75f, {4.0f}}};
  a.interpolation = interpolation;
  return a;
}

TEST(LifeAttributes, RampsTakeTheirKeysValuesExactly) {
  for (const RampInterpolation i :
       {RampInterpolation::Linear, RampInterpolation::Smooth, RampInterpolation::Constant}) {
    const LifeAttributeSettings a = ramp(i);
    EXPECT_EQ(a.evaluate(0, 0.0f, 0.0f), 10.0f);
    EXPECT_EQ(a.evaluate(0, 0.5f, 0.0f), 20.0f);
    EXPECT_EQ(a.evaluate(0, 0.75f, 0.0f), 4.0f);
    EXPECT_EQ(a.evaluate(0, 1.0f, 0.0f), 4.0f) << "after the last key, its value";
    EXPECT_EQ(a.evaluate(0, 2.0f, 0.0f), 4.0f) << "nage clamped to 1";
    EXPECT_EQ(a.evaluate(0, NAN, 0.0f), 10.0f) << "NaN reads as 0";
  }
}

TEST(LifeAttributes, RampsBetweenKeysFollowTheirClosedForms) {
  for (int k = 1; k < 50; ++k) {
    const double n = 0.5 * k / 50.0;  // inside the first segment
    const double w = n / 0.5;
    const auto nage = static_cast<float>(n);
    EXPECT_NEAR(ramp(RampInterpolation::Linear).evaluate(0, nage, 0.0f), 10.0 + 10.0 * w, 2e-6);
    EXPECT_NEAR(ramp(RampInterpolation::Smooth).evaluate(0, nage, 0.0f),
                10.0 + 10.0 * w * w * (3.0 - 2.0 * w), 2e-6);
    EXPECT_EQ(ramp(RampInterpolation::Constant).evaluate(0, nage, 0.0f), 10.0f);
  }
  // The second segment falls: 20 → 4 over [0.5, 0.75].
  EXPECT_NEAR(ramp(RampInterpolation::Linear).evaluate(0, 0.625f, 0.0f), 12.0, 1e-6);
  EXPECT_NEAR(ramp(RampInterpolation::Smooth).evaluate(0, 0.5625f, 0.0f),
              20.0 - 16.0 * (0.0625 * 3.0 - 2.0 * 0.015625), 1e-5);
  EXPECT_EQ(ramp(RampInterpolation::Constant).evaluate(0, 0.7f, 0.0f), 20.0f);
  // Before the first key, the first key's value.
  LifeAttributeSettings late = ramp(RampInterpolation::Linear);
  late.keys[0].nage = 0.25f;
  EXPECT_EQ(late.evaluate(0, 0.1f, 0.0f), 10.0f);
}

TEST(LifeAttributes, NormalisedAgeIsAgeOverLifetimeClamped) {
  EXPECT_EQ(normalisedAge(0.5f, 2.0f), 0.25f);
  EXPECT_EQ(normalisedAge(3.0f, 2.0f), 1.0f);
  EXPECT_EQ(normalisedAge(1.0f, INFINITY), 0.0f);
  EXPECT_EQ(normalisedAge(-1.0f, 2.0f), 0.0f);
}

TEST(LifeAttributes, ValidationNamesTheKeyAndTheRange) {
  LifeAttributeSettings a = ramp(RampInterpolation::Linear);
  a.keys[2].nage = 0.4f;
  ASSERT_EQ(a.validate().size(), 1u);
  EXPECT_EQ(a.validate()[0].text(),
            "ramp.2: nage 0.4 is not after the previous key's 0.5 (expected keys "
            "in rising order of nage)");
  a = ramp(RampInterpolation::Linear);
  a.keys[1].nage = 1.5f;
  EXPECT_EQ(a.validate()[0].text(),
            "ramp.1: nage 1.5 is out of range (expected nage (age / lifetime) from 0 to 1)");
  LifeAttributeSettings cd;
  cd.name = "Cd";
  cd.value = {1.0f, -0.5f, 0.0f};
  EXPECT_EQ(cd.validate()[0].text(),
            "value: -0.5 is out of range (expected a linear RGB colour, each channel >= 0)");
  LifeAttributeSettings alpha;
  alpha.name = "Alpha";
  alpha.value = {1.5f};
  EXPECT_EQ(alpha.validate()[0].text(),
            "value: 1.5 is out of range (expected an opacity from 0 to 1)");
}

std::unique_ptr<ParticleSystem> sparks(std::vector<LifeAttributeSettings> attributes) {
  EmitterSettings e;
  e.name = "sparks";
  e.rate = 600.0;
  e.speed = 1.0;
  e.spreadDegrees = 90.0;
  e.lifetime = 1.0;
  e.lifetimeJitter = 0.5;
  e.attributes = std::move(attributes);
  SystemSettings s;
  s.stepRateHz = 60;
  s.seed = 9;
  return std::make_unique<ParticleSystem>(s, std::vector<EmitterSettings>{e}, test::gravityOnly());
}

// An attribute that is a pure function of the particle adds no column and changes no bit of the
// state: the tick does not know it is there.
TEST(LifeAttributes, CostNothingInTheTick) {
  const auto plain = sparks({});
  const auto ramped = sparks({ramp(RampInterpolation::Smooth)});
  plain->stepTicks(50);
  ramped->stepTicks(50);
  EXPECT_EQ(ramped->pool().attributeCount(), 0u);
  EXPECT_EQ(ramped->pool().bytesPerRow(), plain->pool().bytesPerRow());
  EXPECT_EQ(stateHash(*ramped), stateHash(*plain));
  EXPECT_EQ(ramped->attributeNames(), std::vector<std::string>{"heat"});
}

// Shown values are the ramp at each particle's age at the shown time over its own lifetime;
// random ranges draw from (seed, emitter, id).
TEST(LifeAttributes, ShownValuesAreEvaluatedAtTheShownAge) {
  LifeAttributeSettings size;
  size.name = "pscale";
  size.kind = LifeAttributeSettings::Kind::Random;
  size.value = {0.01f};
  size.high = {0.03f};
  const auto system = sparks({ramp(RampInterpolation::Linear), size});
  system->advance(kFlicksPerSecond / 24 * 10 + kFlicksPerSecond / 100);  // between two ticks
  const std::size_t n = system->pool().size();
  ASSERT_GT(n, 10u);
  ASSERT_LT(system->alpha(), 1.0f);
  std::vector<float> heat(n), pscale(n);
  FloatColumn ages;
  system->renderAges(ages);
  ASSERT_TRUE(system->copyColumn("heat", FloatDestination{heat.data(), sizeof(float), n}));
  ASSERT_TRUE(system->copyColumn("pscale", FloatDestination{pscale.data(), sizeof(float), n}));
  const LifeAttributeSettings expect = ramp(RampInterpolation::Linear);
  for (std::size_t i = 0; i < n; ++i) {
    const auto r = static_cast<Eigen::Index>(i);
    const float nage = normalisedAge(ages[r], system->pool().lifetime()[r]);
    EXPECT_EQ(heat[i], expect.evaluate(0, nage, 0.0f)) << "row " << i;
    const float u =
        unitFromBits(ParticleRandom(9, 0, system->pool().id()[i])
                         .bits(static_cast<std::uint32_t>(RandomPurpose::Attribute) + 1));
    EXPECT_EQ(pscale[i], 0.01f + (0.03f - 0.01f) * u);
    EXPECT_GE(pscale[i], 0.01f);
    EXPECT_LT(pscale[i], 0.03f);
  }
  EXPECT_NE(pscale[0], pscale[1]);
}

}  // namespace
}  // namespace tickfx

// TICKFX_ASSERT: evaluated where the build says so (the sanitizer build), reported to the host's
// hook with file, line and condition; compiled to nothing otherwise.
#include <gtest/gtest.h>

#include <cstring>
#include <string>

#include "fields/ForceModule.h"
#include "integrators/StagePasses.h"
#include "particles/Assert.h"

namespace tickfx {
namespace {

struct Caught {
  AssertFailure failure;
};

void throwingHook(const AssertFailure& failure) { throw Caught{failure}; }

// Installs the throwing hook for one test and puts the previous one back.
class Assert : public ::testing::Test {
 protected:
  void SetUp() override { previous_ = setAssertHook(throwingHook); }
  void TearDown() override { setAssertHook(previous_); }

  // What a failed assertion in `f` reported, or "" when none fired.
  template <typename F>
  static std::string reported(F&& f) {
    try {
      f();
    } catch (const Caught& c) {
      return std::string(std::strrchr(c.failure.file, '/') + 1) + ": " + c.failure.condition +
             " (" + c.failure.message + ")";
    }
    return "";
  }

  AssertHook previous_ = nullptr;
};

TEST_F(Assert, ConditionsAreEvaluatedOnlyWhereTheBuildSays) {
  int evaluated = 0;
  TICKFX_ASSERT((++evaluated, true), "counts its evaluations");
  EXPECT_EQ(evaluated, kAssertsEnabled ? 1 : 0);
}

TEST_F(Assert, AViewReadBelowItsBaseReachesTheHook) {
  const float values[4] = {1, 2, 3, 4};
  const Vec3View view{values, values, values, 10};
  const std::string expected =
      kAssertsEnabled ? "RowViews.h: row >= base (a row read below a view's base)" : "";
  EXPECT_EQ(reported([&] {
              if constexpr (kAssertsEnabled) view.at(5);  // undefined behaviour when unchecked
            }),
            expected);
  EXPECT_EQ(reported([&] { return view.at(11); }), "");
}

TEST_F(Assert, AStageColumnOutOfRangeReachesTheHook) {
  StageScratch scratch(2);
  EXPECT_EQ(reported([&] { scratch.column(1); }), "");
  EXPECT_EQ(reported([&] {
              if constexpr (kAssertsEnabled) scratch.column(2);
            }),
            kAssertsEnabled ? "StagePasses.h: k >= 0 && k < count_ (a stage column this "
                              "integrator did not ask for)"
                            : "");
}

TEST_F(Assert, ARowRangePastItsColumnReachesTheHook) {
  Vec3Column column;
  column.resize(8);
  EXPECT_EQ(reported([&] { Vec3Rows::of(column, RowRange{2, 8}); }), "");
  EXPECT_EQ(reported([&] {
              if constexpr (kAssertsEnabled) Vec3Rows::of(column, RowRange{2, 9});
            }),
            kAssertsEnabled ? "RowViews.h: r.begin <= r.end && r.end <= "
                              "static_cast<std::size_t>(c.x.size()) (a row range past the end "
                              "of its column)"
                            : "");
}

}  // namespace
}  // namespace tickfx

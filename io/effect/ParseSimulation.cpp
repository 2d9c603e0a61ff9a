#include "io/effect/ParseSimulation.h"

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "integrators/Integrator.h"
#include "io/effect/EffectSettings.h"
#include "particles/NonfiniteState.h"

namespace tickfx::io::detail {
namespace {

constexpr std::int64_t kMaxStepRate = 1'000'000;
constexpr std::int64_t kMaxParticles = 1'000'000'000;
constexpr std::int64_t kMaxTicksPerFrame = 100'000;

const std::vector<std::string> kOverrunPolicies = {"drop", "fall_behind"};

}  // namespace

void readSimulation(Context& cx, const toml::table& table, SystemSettings& s) {
  TableReader r(cx, table, "simulation");
  r.integer("step_rate", s.stepRateHz, "ticks per second (Hz), an integer from 1 to 1000000", 1,
            kMaxStepRate, /*required=*/true);
  r.choice("integrator", s.integrator, integratorNames(), "integrator");
  r.integer("seed", s.seed, "an integer from 0 to 9223372036854775807", 0,
            std::numeric_limits<std::int64_t>::max());
  r.integer("max_particles", s.maxParticles, "an integer from 1 to 1000000000", 1, kMaxParticles);
  r.integer("max_ticks_per_frame", s.maxTicksPerFrame, "an integer from 1 to 100000", 1,
            kMaxTicksPerFrame);
  std::string overrun;
  if (r.choice("overrun", overrun, kOverrunPolicies, "overrun policy")) {
    s.overrunPolicy = overrun == "drop" ? OverrunPolicy::DropExcess : OverrunPolicy::FallBehind;
  }
  r.integer("threads", s.threads, "worker threads, an integer from 0 (all cores) to 1024", 0,
            kMaxThreads);
  std::string nonfinite;
  if (r.choice("nonfinite", nonfinite, nonfinitePolicyNames(), "nonfinite policy")) {
    s.nonfinite = nonfinitePolicyNamed(nonfinite);
  }
  r.finish();
}

}  // namespace tickfx::io::detail

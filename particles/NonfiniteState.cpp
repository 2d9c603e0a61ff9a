#include "particles/NonfiniteState.h"

#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace tickfx {

const std::vector<std::string>& nonfinitePolicyNames() {
  static const std::vector<std::string> names{"stop", "kill", "keep"};
  return names;
}

NonfinitePolicy nonfinitePolicyNamed(std::string_view name) {
  const std::vector<std::string>& names = nonfinitePolicyNames();
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (names[i] == name) return static_cast<NonfinitePolicy>(i);
  }
  throw std::invalid_argument("nonfinite policy \"" + std::string(name) +
                              "\" is not one of stop, kill, keep");
}

std::string_view nameOf(NonfinitePolicy policy) {
  return nonfinitePolicyNames()[static_cast<std::size_t>(policy)];
}

std::string NonfiniteEvent::describe() const {
  char time[64];
  std::snprintf(time, sizeof time, "%.9g", seconds());
  std::string text = "tick " + std::to_string(tick) + " (t = " + time +
                     " s): " + std::to_string(particles) +
                     (particles == 1 ? " particle has" : " particles have") +
                     " a non-finite position or velocity (" + (firstIds.size() == 1 ? "id" : "ids");
  for (std::size_t i = 0; i < firstIds.size(); ++i) {
    text += (i == 0 ? " " : ", ") + std::to_string(firstIds[i]);
  }
  return text + (particles > firstIds.size() ? ", ...)" : ")");
}

void NonfiniteCheck::scan(ParticlePool& pool, std::size_t begin, std::size_t end) {
  // The quick test: a sum of finite floats is finite unless it overflows, and a ±inf or NaN makes
  // it non-finite. Eigen's sum() runs in packets (one load and one add per four values), about
  // half the work of testing each value's exponent; an overflow only sends a tile to the exact
  // test below, which flags nothing.
  const auto n = static_cast<Eigen::Index>(end - begin);
  const auto first = static_cast<Eigen::Index>(begin);
  const Vec3Column& p = pool.position();
  const Vec3Column& v = pool.velocity();
  // One reduction over the six columns' row sums: the adds within a row are independent, so the
  // loop is bound by loads, not by the latency of one running sum per column.
  const float sum = ((p.x.segment(first, n) + p.y.segment(first, n)) +
                     (p.z.segment(first, n) + v.x.segment(first, n)) +
                     (v.y.segment(first, n) + v.z.segment(first, n)))
                        .sum();
  if (std::isfinite(sum)) return;
  std::uint8_t* dead = pool.dead().data();
  for (std::size_t i = begin; i < end; ++i) {
    const auto r = static_cast<Eigen::Index>(i);
    bool ok = true;
    for (const Vec3Column* column : {&pool.position(), &pool.velocity()}) {
      for (int c = 0; c < 3; ++c) ok = ok && std::isfinite((*column)[c][r]);
    }
    if (!ok) {
      dead[i] = static_cast<std::uint8_t>(dead[i] | kFlag);
      found_.raise();
    }
  }
}

}  // namespace tickfx

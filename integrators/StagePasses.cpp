#include "integrators/StagePasses.h"

#include <algorithm>
#include <vector>

#include "particles/ParallelFor.h"

namespace tickfx {

void runPasses(std::size_t rows, bool fused, std::initializer_list<RowPass> passes) {
  if (fused) {
    parallelForRows(rows, [&](std::size_t b, std::size_t e) {
      for (const RowPass& pass : passes) pass(RowRange{b, e});
    });
    return;
  }
  for (const RowPass& pass : passes) {
    parallelForRows(rows, [&](std::size_t b, std::size_t e) { pass(RowRange{b, e}); });
  }
}

RowRange intersect(RowRange r, std::size_t begin, std::size_t end) {
  const std::size_t b = std::max(r.begin, begin);
  const std::size_t e = std::min(r.end, end);
  return b < e ? RowRange{b, e} : RowRange{b, b};
}

void ensureRows(Vec3Column& c, std::size_t rows) {
  if (static_cast<std::size_t>(c.x.size()) < rows) c.resize(static_cast<Eigen::Index>(rows));
}

}  // namespace tickfx

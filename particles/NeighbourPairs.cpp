#include "particles/NeighbourPairs.h"

#include <algorithm>
#include <cmath>

namespace tickfx {

std::vector<std::pair<int, int>> neighbourPairs(const std::vector<Eigen::Vector3d>& points,
                                                double distance, std::uint64_t* compared) {
  std::vector<std::pair<int, int>> pairs;
  if (compared != nullptr) *compared = 0;
  const auto n = static_cast<int>(points.size());
  if (n < 2) return pairs;

  Eigen::Vector3d lo = points[0], hi = points[0];
  for (const Eigen::Vector3d& p : points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  // At most ⌈∛n⌉ cells along an axis: a tiny distance widens the cells instead of multiplying
  // them (a link radius of 1e-30 would otherwise index cells far beyond any integer).
  const int most = std::max(1, static_cast<int>(std::ceil(std::cbrt(static_cast<double>(n)))));
  // Cells a little wider than `distance`: two points within it are then at most one cell apart
  // on every axis, even after (x − lo) / cell rounds (an error of about most · 2⁻⁵³ of a cell,
  // 2⁻⁴⁶ for a cluster's ∛10⁶ = 100 cells, far inside the 2⁻³⁰ margin).
  const double cell = std::max(distance, (hi - lo).maxCoeff() / most) * (1.0 + 0x1p-30);
  Eigen::Array3i cells;
  for (int c = 0; c < 3; ++c) {
    cells[c] = std::min(most, static_cast<int>(std::floor((hi[c] - lo[c]) / cell)) + 1);
  }
  // The cell of each point, clamped in double before the conversion to int (which is then always
  // defined); the clamp never parts points that are within `distance`: it moves neither closer
  // to the other by more than their gap.
  const auto cellOf = [&](const Eigen::Vector3d& p) {
    Eigen::Array3i at;
    for (int c = 0; c < 3; ++c) {
      const double t = std::floor((p[c] - lo[c]) / cell);
      at[c] = static_cast<int>(std::clamp(t, 0.0, static_cast<double>(cells[c] - 1)));
    }
    return at;
  };
  const auto flat = [&](const Eigen::Array3i& at) {
    return (static_cast<std::size_t>(at.x()) * cells.y() + at.y()) * cells.z() + at.z();
  };

  // Points sorted by cell (a counting sort; within a cell in index order): cell k holds
  // members[first[k]] to members[first[k + 1] − 1].
  const std::size_t count = static_cast<std::size_t>(cells.x()) * cells.y() * cells.z();
  std::vector<int> first(count + 1, 0), members(points.size());
  std::vector<Eigen::Array3i> at(points.size());
  for (int i = 0; i < n; ++i) {
    at[i] = cellOf(points[i]);
    ++first[flat(at[i]) + 1];
  }
  for (std::size_t k = 0; k < count; ++k) first[k + 1] += first[k];
  std::vector<int> next(first.begin(), first.end() - 1);
  for (int i = 0; i < n; ++i) members[next[flat(at[i])]++] = i;

  std::uint64_t work = 0;
  std::vector<int> near;
  for (int i = 0; i < n; ++i) {
    near.clear();
    const Eigen::Array3i lower = (at[i] - 1).max(0), upper = (at[i] + 1).min(cells - 1);
    for (int x = lower.x(); x <= upper.x(); ++x) {
      for (int y = lower.y(); y <= upper.y(); ++y) {
        for (int z = lower.z(); z <= upper.z(); ++z) {
          const std::size_t k = flat(Eigen::Array3i(x, y, z));
          for (int m = first[k]; m < first[k + 1]; ++m) {
            const int j = members[m];
            if (j <= i) continue;
            ++work;
            if ((points[j] - points[i]).norm() <= distance) near.push_back(j);
          }
        }
      }
    }
    // Sorted per point, so the whole list is in (i, j) order without sorting every pair.
    std::sort(near.begin(), near.end());
    for (const int j : near) pairs.emplace_back(i, j);
  }
  if (compared != nullptr) *compared = work;
  return pairs;
}

}  // namespace tickfx

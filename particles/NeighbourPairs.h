// Every pair of points within a distance of each other, found through a bounded grid of cells.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <utility>
#include <vector>

namespace tickfx {

/// Every pair (i, j), i < j, of `points` at most `distance` apart, (points[j] − points[i]).norm()
/// <= distance in double, sorted by i then j: the same list as comparing every pair, whatever the
/// order points are binned in.
///
/// Points are binned into a grid over their bounding box: cells at least `distance` wide (a
/// little wider, so that rounding cannot put a pair within `distance` two cells apart), widened
/// when `distance` is small against the box so that there are at most ⌈∛N⌉ cells along any axis
/// (about N cells in all). Each point is compared with the points of its own and the 26
/// surrounding cells. Every cell index is in range whatever `distance` (> 0; 1e-30 is fine), and
/// for points spread through the box (a cluster's) the work is linear in the points and the pairs
/// found. `distance` must be > 0 and finite, and the points finite.
///
/// `compared`, when given, receives how many pairs' distances were computed: the search's work,
/// which the tests bound.
std::vector<std::pair<int, int>> neighbourPairs(const std::vector<Eigen::Vector3d>& points,
                                                double distance, std::uint64_t* compared = nullptr);

}  // namespace tickfx

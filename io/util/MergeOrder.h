// The order that merges sorted lists into one: what merging shards by id needs, for frames,
// checkpoint rows and springs alike.
#pragma once

#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

namespace tickfx::io {

/// (list, index) of every element of `sizes.size()` lists, list s holding sizes[s] elements whose
/// keys key(s, i) rise, in the order of their keys: a k-way merge. Equal keys from two lists call
/// tie(s, t, key) with s the later list and t the one taken (it may throw), then take t's first.
/// Linear in the elements times the lists (a few lists: shards), never allocating but the result.
template <typename Key, typename Tie>
std::vector<std::pair<std::uint32_t, std::uint64_t>> mergeOrder(
    const std::vector<std::uint64_t>& sizes, Key key, Tie tie) {
  std::uint64_t total = 0;
  for (const std::uint64_t n : sizes) total += n;
  std::vector<std::pair<std::uint32_t, std::uint64_t>> order;
  order.reserve(static_cast<std::size_t>(total));
  std::vector<std::uint64_t> next(sizes.size(), 0);
  for (std::uint64_t k = 0; k < total; ++k) {
    std::size_t best = sizes.size();
    for (std::size_t s = 0; s < sizes.size(); ++s) {
      if (next[s] == sizes[s]) continue;
      if (best == sizes.size()) {
        best = s;
        continue;
      }
      const auto a = key(s, next[s]), b = key(best, next[best]);
      if (a < b) {
        best = s;
      } else if (a == b) {
        tie(s, best, a);
      }
    }
    order.emplace_back(static_cast<std::uint32_t>(best), next[best]++);
  }
  return order;
}

}  // namespace tickfx::io

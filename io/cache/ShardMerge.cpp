#include "io/cache/ShardMerge.h"

#include <stdexcept>
#include <string>

#include "io/util/MergeOrder.h"

namespace tickfx::io {
namespace {

[[noreturn]] void refuse(const std::filesystem::path& path, const std::string& what) {
  throw std::runtime_error(path.string() + ": error: " + what);
}

// Copies row `from` of `source` into row `to` of `out` (sized, same attribute names).
void copyRow(const FrameData& source, std::size_t from, FrameData& out, std::size_t to) {
  const auto f = static_cast<Eigen::Index>(from), t = static_cast<Eigen::Index>(to);
  out.id[to] = source.id[from];
  for (int c = 0; c < 3; ++c) {
    out.position[c][t] = source.position[c][f];
    out.velocity[c][t] = source.velocity[c][f];
  }
  out.age[t] = source.age[f];
  out.life[t] = source.life[f];
  out.mass[t] = source.mass[f];
  for (std::size_t a = 0; a < out.attributes.size(); ++a)
    out.attributes[a][t] = source.attributes[a][f];
}

}  // namespace

FrameData mergeShardFrames(const std::vector<FrameData>& shards,
                           const std::vector<std::filesystem::path>& sources) {
  if (shards.empty()) throw std::invalid_argument("mergeShardFrames: no shards");
  const FrameData& first = shards.front();
  std::size_t total = 0;
  for (std::size_t s = 0; s < shards.size(); ++s) {
    const FrameData& f = shards[s];
    if (f.frame != first.frame || f.timeSeconds != first.timeSeconds) {
      refuse(sources[s], "frame " + std::to_string(f.frame) + " beside frame " +
                             std::to_string(first.frame) + " of " + sources.front().string());
    }
    if (f.attributeNames != first.attributeNames)
      refuse(sources[s], "other attributes than " + sources.front().string());
    total += f.size();
  }
  // Each shard's rows rise by id: a k-way merge gives the whole run's order.
  std::vector<std::uint64_t> sizes;
  for (const FrameData& f : shards) sizes.push_back(f.size());
  const auto order = mergeOrder(
      sizes, [&](std::size_t s, std::uint64_t row) { return shards[s].id[row]; },
      [&](std::size_t s, std::size_t t, std::uint64_t id) {
        refuse(sources[s],
               "particle " + std::to_string(id) + " is in " + sources[t].string() + " too");
      });
  FrameData out;
  out.frame = first.frame;
  out.timeSeconds = first.timeSeconds;
  out.resize(total, first.attributeNames);
  for (std::size_t row = 0; row < order.size(); ++row)
    copyRow(shards[order[row].first], order[row].second, out, row);
  return out;
}

}  // namespace tickfx::io

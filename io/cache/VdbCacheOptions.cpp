#include "io/cache/VdbCacheOptions.h"

#include <algorithm>

namespace tickfx::io {
namespace {

template <typename Enum>
std::optional<Enum> named(const std::vector<std::string>& names, std::string_view name) {
  const auto it = std::find(names.begin(), names.end(), name);
  if (it == names.end()) return std::nullopt;
  return static_cast<Enum>(it - names.begin());
}

}  // namespace

std::string_view vdbCompressionName(VdbCacheOptions::Compression compression) {
  return vdbCompressionNames()[static_cast<std::size_t>(compression)];
}

const std::vector<std::string>& vdbCompressionNames() {
  static const std::vector<std::string> names = {"none", "blosc"};
  return names;
}

std::string_view vdbPositionsName(VdbCacheOptions::Positions positions) {
  return vdbPositionsNames()[static_cast<std::size_t>(positions)];
}

const std::vector<std::string>& vdbPositionsNames() {
  static const std::vector<std::string> names = {"exact", "fixed16"};
  return names;
}

std::optional<VdbCacheOptions::Compression> vdbCompressionNamed(std::string_view name) {
  return named<VdbCacheOptions::Compression>(vdbCompressionNames(), name);
}

std::optional<VdbCacheOptions::Positions> vdbPositionsNamed(std::string_view name) {
  return named<VdbCacheOptions::Positions>(vdbPositionsNames(), name);
}

}  // namespace tickfx::io

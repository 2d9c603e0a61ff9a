#include "io/effect/SourceMap.h"

namespace tickfx::io {

void SourceMap::set(std::string keyPath, SourceLocation location) {
  locations_.insert_or_assign(std::move(keyPath), std::move(location));
}

SourceLocation SourceMap::find(std::string_view keyPath) const {
  while (true) {
    if (auto it = locations_.find(keyPath); it != locations_.end()) return it->second;
    if (keyPath.empty()) return {};
    const std::size_t dot = keyPath.rfind('.');
    keyPath = dot == std::string_view::npos ? std::string_view() : keyPath.substr(0, dot);
  }
}

bool SourceMap::contains(std::string_view keyPath) const {
  return locations_.find(keyPath) != locations_.end();
}

}  // namespace tickfx::io

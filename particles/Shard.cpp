#include "particles/Shard.h"

#include <charconv>
#include <stdexcept>
#include <system_error>

namespace tickfx {

std::optional<std::string> Shard::problem() const {
  if (count < 1 || count > kMaxCount) {
    return "the count " + std::to_string(count) + " is not from 1 to " + std::to_string(kMaxCount);
  }
  if (index >= count) {
    return "index " + std::to_string(index) + " is not below the count " + std::to_string(count);
  }
  return std::nullopt;
}

std::string Shard::text() const { return std::to_string(index) + "/" + std::to_string(count); }

Shard Shard::parse(const std::string& text) {
  const std::size_t slash = text.find('/');
  const auto whole = [&](std::size_t begin, std::size_t end, std::uint32_t& out) {
    const char* first = text.data() + begin;
    const char* last = text.data() + end;
    const auto [ptr, ec] = std::from_chars(first, last, out);
    return begin < end && ec == std::errc() && ptr == last;
  };
  Shard s;
  if (slash == std::string::npos || !whole(0, slash, s.index) ||
      !whole(slash + 1, text.size(), s.count)) {
    throw std::invalid_argument("'" + text + "' is not I/N (shard I of N, from 0)");
  }
  if (const std::optional<std::string> p = s.problem()) {
    throw std::invalid_argument("'" + text + "': " + *p);
  }
  return s;
}

}  // namespace tickfx

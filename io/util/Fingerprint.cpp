#include "io/util/Fingerprint.h"

#include <algorithm>
#include <cstring>
#include <fstream>
#include <iterator>

namespace tickfx::io {

namespace {

std::uint64_t mix(std::uint64_t h, std::uint64_t word) {
  h = (h ^ word) * 0x100000001b3ULL;
  h ^= h >> 29;
  h *= 0xbf58476d1ce4e5b9ULL;
  h ^= h >> 32;
  return h;
}

std::uint64_t littleEndianWord(const char* p) {
  std::uint64_t v = 0;
  for (int i = 7; i >= 0; --i) v = (v << 8) | static_cast<unsigned char>(p[i]);
  return v;
}

}  // namespace

std::uint64_t fingerprint(std::string_view bytes) {
  Fingerprinter f;
  f.add(bytes);
  return f.value();
}

void Fingerprinter::add(std::string_view bytes) {
  count_ += bytes.size();
  std::size_t i = 0;
  if (pendingSize_ > 0) {
    const std::size_t take = std::min(bytes.size(), 8 - pendingSize_);
    std::memcpy(pending_ + pendingSize_, bytes.data(), take);
    pendingSize_ += take;
    i = take;
    if (pendingSize_ < 8) return;
    h_ = mix(h_, littleEndianWord(pending_));
    pendingSize_ = 0;
  }
  for (; i + 8 <= bytes.size(); i += 8) h_ = mix(h_, littleEndianWord(bytes.data() + i));
  pendingSize_ = bytes.size() - i;
  if (pendingSize_ > 0) std::memcpy(pending_, bytes.data() + i, pendingSize_);
}

std::uint64_t Fingerprinter::value() const {
  std::uint64_t h = h_;
  if (pendingSize_ > 0) {
    char tail[8] = {};
    std::memcpy(tail, pending_, pendingSize_);
    h = mix(h, littleEndianWord(tail));
  }
  // Without the length, inputs that differ only by trailing zero bytes would collide.
  return mix(h, count_);
}

std::uint64_t effectFingerprint(std::string_view effectText,
                                const std::vector<std::string>& overrides) {
  std::string bytes(effectText);
  for (const std::string& o : overrides) bytes += '\0' + o;
  return fingerprint(bytes);
}

std::uint64_t effectFileFingerprint(const std::filesystem::path& effectFile,
                                    const std::vector<std::string>& overrides) {
  std::ifstream in(effectFile, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  return effectFingerprint(std::string_view(bytes), overrides);
}

}  // namespace tickfx::io

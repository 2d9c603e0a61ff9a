// Little-endian integers read from and written into a file's bytes: the tests that edit a
// checkpoint (and the fuzzer that seeds from one) patch its fields in place.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace tickfx::test {

inline std::uint64_t loadU64(const std::string& bytes, std::size_t at) {
  std::uint64_t v = 0;
  for (int i = 7; i >= 0; --i) v = (v << 8) | static_cast<unsigned char>(bytes[at + i]);
  return v;
}

inline void storeU64(std::string& bytes, std::size_t at, std::uint64_t v) {
  for (int i = 0; i < 8; ++i) bytes[at + i] = static_cast<char>((v >> (8 * i)) & 0xff);
}

inline void storeU32(std::string& bytes, std::size_t at, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) bytes[at + i] = static_cast<char>((v >> (8 * i)) & 0xff);
}

}  // namespace tickfx::test

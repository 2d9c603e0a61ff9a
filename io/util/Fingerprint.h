// The 64-bit fingerprint of bytes: effect identities in checkpoints, VDB caches and hash logs,
// and the checksum of checkpoint files.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace tickfx::io {

/// A 64-bit non-cryptographic fingerprint of `bytes`.
///
/// Stable across versions and platforms (it is part of the file formats): starting from
/// h = 0xcbf29ce484222325, each 8-byte little-endian word w of the input (the last one padded
/// with zero bytes) is mixed in as h = (h ^ w) · 0x100000001b3, h ^= h >> 29,
/// h *= 0xbf58476d1ce4e5b9, h ^= h >> 32; then the byte count is mixed in the same way. Every
/// step is a bijection of h, so any change confined to one word always changes the result.
std::uint64_t fingerprint(std::string_view bytes);

/// fingerprint() of bytes given a piece at a time: add() the pieces in order, then value() is
/// fingerprint() of them all joined (for files written as they are made).
class Fingerprinter {
 public:
  void add(std::string_view bytes);
  std::uint64_t value() const;

 private:
  std::uint64_t h_ = 0xcbf29ce484222325ULL;
  std::uint64_t count_ = 0;  // bytes added
  char pending_[8] = {};     // the bytes of an unfinished word
  std::size_t pendingSize_ = 0;
};

/// The effect as a checkpoint, a VDB cache and a hash log know it: fingerprint() of the effect
/// file's bytes and every override, in order, each after a zero byte. loadEffectFile() and
/// parseEffect() give it for the text they parsed (LoadResult::fingerprint).
std::uint64_t effectFingerprint(std::string_view effectText,
                                const std::vector<std::string>& overrides);

/// effectFingerprint() of the file at `effectFile` as it reads now (as empty text when it cannot
/// be read).
std::uint64_t effectFileFingerprint(const std::filesystem::path& effectFile,
                                    const std::vector<std::string>& overrides);

}  // namespace tickfx::io

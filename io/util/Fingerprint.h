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

/// Bytes a piece of piecewiseFingerprint() holds: 1 MiB.
inline constexpr std::size_t kFingerprintPieceBytes = std::size_t{1} << 20;

/// A 64-bit fingerprint of `bytes` whose work splits over threads: `bytes` cut into pieces of
/// kFingerprintPieceBytes (the last one shorter, none for no bytes), each piece's fingerprint()
/// taken in parallel, then the Fingerprinter of the byte count and the pieces' fingerprints in
/// order, each as 8 little-endian bytes. Stable across versions and platforms (the checksum of
/// checkpoint files since format 4), and the same on any thread count.
std::uint64_t piecewiseFingerprint(std::string_view bytes);

/// piecewiseFingerprint() of bytes given a piece at a time: add() them in order, then value() is
/// piecewiseFingerprint() of them all joined. Bytes are held until 64 pieces are whole, which
/// are then fingerprinted in parallel.
class PiecewiseFingerprinter {
 public:
  void add(std::string_view bytes);
  std::uint64_t value() const;

 private:
  void takeWholePieces();
  std::string held_;                   // bytes not yet in a piece's fingerprint
  std::vector<std::uint64_t> pieces_;  // fingerprints of the pieces so far
  std::uint64_t count_ = 0;            // bytes added
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

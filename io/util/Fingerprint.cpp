#include "io/util/Fingerprint.h"

#include <algorithm>
#include <cstring>
#include <fstream>
#include <iterator>

#include "particles/ParallelFor.h"

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

namespace {

// The pieces' fingerprints of whole pieces of `bytes` (and of a shorter last one when `last`).
void fingerprintPieces(std::string_view bytes, bool last, std::vector<std::uint64_t>& out) {
  const std::size_t whole = bytes.size() / kFingerprintPieceBytes;
  const std::size_t count = whole + (last && bytes.size() % kFingerprintPieceBytes != 0 ? 1 : 0);
  const std::size_t first = out.size();
  out.resize(first + count);
  parallelForTasks(count, [&](std::size_t i) {
    out[first + i] = fingerprint(bytes.substr(i * kFingerprintPieceBytes, kFingerprintPieceBytes));
  });
}

std::uint64_t combinePieces(std::uint64_t count, const std::vector<std::uint64_t>& pieces) {
  Fingerprinter f;
  char word[8];
  const auto addWord = [&](std::uint64_t v) {
    for (int i = 0; i < 8; ++i) word[i] = static_cast<char>((v >> (8 * i)) & 0xff);
    f.add(std::string_view(word, 8));
  };
  addWord(count);
  for (const std::uint64_t piece : pieces) addWord(piece);
  return f.value();
}

// Pieces fingerprinted at once by PiecewiseFingerprinter (64 MiB held at most).
constexpr std::size_t kPiecesAtOnce = 64;

}  // namespace

std::uint64_t piecewiseFingerprint(std::string_view bytes) {
  std::vector<std::uint64_t> pieces;
  fingerprintPieces(bytes, /*last=*/true, pieces);
  return combinePieces(bytes.size(), pieces);
}

void PiecewiseFingerprinter::add(std::string_view bytes) {
  count_ += bytes.size();
  while (!bytes.empty()) {
    const std::size_t room = kPiecesAtOnce * kFingerprintPieceBytes - held_.size();
    const std::size_t take = std::min(room, bytes.size());
    held_.append(bytes.data(), take);
    bytes.remove_prefix(take);
    if (held_.size() == kPiecesAtOnce * kFingerprintPieceBytes) takeWholePieces();
  }
}

void PiecewiseFingerprinter::takeWholePieces() {
  fingerprintPieces(held_, /*last=*/false, pieces_);
  held_.erase(0, held_.size() / kFingerprintPieceBytes * kFingerprintPieceBytes);
}

std::uint64_t PiecewiseFingerprinter::value() const {
  std::vector<std::uint64_t> pieces = pieces_;
  fingerprintPieces(held_, /*last=*/true, pieces);
  return combinePieces(count_, pieces);
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

// What the tests of damaged .vdb files share: every one-bit corruption of a file, each loaded on
// its own. OpenVDB 10 trusts the sizes, counts and flags it reads, so tickfx checks every byte
// first; these loops are how the tests show that no flipped bit gets past the checks.
#pragma once

#include <gtest/gtest.h>

#include <cstddef>
#include <exception>
#include <filesystem>
#include <fstream>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

namespace tickfx::test {

/// What loading every flipped-bit copy of a file gave: how many loaded, and each refusal's message.
struct FlippedBits {
  std::size_t loaded = 0;
  std::vector<std::string> refusals;
};

/// For each byte i of `bytes`: writes `bytes` with bit i mod 8 of byte i flipped as the file
/// fileFor(i), calls load(file, i), and removes the file. load returns normally (the file
/// loaded; it checks what it loaded itself) or throws. A std::runtime_error is a refusal, whose
/// message must begin with "FILE: grid 'GRID': " (the file and grid named); any other exception
/// is a test failure and counts as neither.
inline FlippedBits loadEveryFlippedBit(
    const std::string& bytes, const std::function<std::string(std::size_t)>& fileFor,
    const std::string& grid,
    const std::function<void(const std::string& file, std::size_t byte)>& load) {
  FlippedBits out;
  for (std::size_t i = 0; i < bytes.size(); ++i) {
    std::string flipped = bytes;
    flipped[i] = static_cast<char>(flipped[i] ^ (1 << (i % 8)));
    const std::string file = fileFor(i);
    std::ofstream(file, std::ios::binary) << flipped;
    try {
      load(file, i);
      ++out.loaded;
    } catch (const std::runtime_error& e) {
      const std::string what = e.what();
      EXPECT_EQ(what.rfind(file + ": grid '" + grid + "': ", 0), 0u)
          << "byte " << i << ": " << what;
      out.refusals.push_back(what);
    } catch (const std::exception& e) {
      ADD_FAILURE() << "byte " << i << ": not a runtime_error: " << e.what();
    }
    std::filesystem::remove(file);
  }
  return out;
}

}  // namespace tickfx::test

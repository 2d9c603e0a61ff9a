// A whole file's bytes, for the tests that compare or alter what a writer wrote.
#pragma once

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

namespace tickfx::test {

/// Every byte of the file at `path`, as written (binary); empty when it cannot be opened.
inline std::string fileBytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

}  // namespace tickfx::test

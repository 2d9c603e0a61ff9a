// Where each setting of an effect came from, so that checks made after parsing (lint) can point
// at the text.
#pragma once

#include <functional>
#include <map>
#include <string>
#include <string_view>

namespace tickfx::io {

/// A place in an effect file (line and column 1-based), or, with line 0, an origin outside it:
/// `file` is then "--set key.path" for a value given as an override.
struct SourceLocation {
  std::string file;
  int line = 0;
  int column = 0;
};

/// Key path ("forces.1.frequency") → where its value was written. Tables are recorded at their
/// header ("forces.1"), the whole file at "" (line 1, column 1).
class SourceMap {
 public:
  void set(std::string keyPath, SourceLocation location);

  /// The location of `keyPath`, or of its nearest recorded ancestor when the key was not
  /// written (a default), or an empty location when nothing is recorded.
  SourceLocation find(std::string_view keyPath) const;

  /// True when `keyPath` itself was written (not defaulted).
  bool contains(std::string_view keyPath) const;

 private:
  std::map<std::string, SourceLocation, std::less<>> locations_;
};

}  // namespace tickfx::io

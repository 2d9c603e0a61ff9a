// Errors and warnings about an effect file, in the one format every tool prints.
#pragma once

#include <string>
#include <vector>

namespace tickfx::io {

enum class Severity { Error, Warning };

/// One finding about an effect file. format() gives exactly
///   FILE:LINE:COL: error: key.path: what is wrong (what is expected)
/// Positions are 1-based and point at the offending value (at the key for an unknown key, at the
/// enclosing table's header for a missing key). A finding without a line (line == 0) is not in
/// the file: `file` then names its origin, "--set key.path" for a value given as an override or
/// the path of a file that could not be read, and the position is left out of format().
struct Diagnostic {
  Severity severity = Severity::Error;
  std::string file;
  int line = 0;
  int column = 0;
  std::string keyPath;  // "emitters.0.rate"; empty when the finding is about the text (bad TOML)
  std::string message;  // "what is wrong (what is expected)"

  std::string format() const;
};

/// True when any diagnostic is an error (warnings do not stop a load).
bool hasErrors(const std::vector<Diagnostic>& diagnostics);

/// Orders findings as a reader meets them: by line and column in the file, findings from
/// overrides (line 0) last, in their original order.
void sortDiagnostics(std::vector<Diagnostic>& diagnostics);

/// A number as messages print it: integers without a fraction ("20", "-3"), others with the
/// shortest digits that read back to the same double ("0.1", "1e+20"), "nan", "inf", "-inf".
std::string formatNumber(double value);

}  // namespace tickfx::io

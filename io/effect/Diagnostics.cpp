#include "io/effect/Diagnostics.h"

#include <algorithm>
#include <charconv>
#include <cmath>

namespace tickfx::io {

std::string Diagnostic::format() const {
  // Appended piece by piece: GCC 12 warns falsely (-Wrestrict) on "x" + std::string chains.
  std::string out = file;
  if (line > 0) {
    out.append(":").append(std::to_string(line));
    out.append(":").append(std::to_string(column));
  }
  out.append(severity == Severity::Error ? ": error: " : ": warning: ");
  if (!keyPath.empty()) out.append(keyPath).append(": ");
  out.append(message);
  return out;
}

bool hasErrors(const std::vector<Diagnostic>& diagnostics) {
  return std::any_of(diagnostics.begin(), diagnostics.end(),
                     [](const Diagnostic& d) { return d.severity == Severity::Error; });
}

void sortDiagnostics(std::vector<Diagnostic>& diagnostics) {
  std::stable_sort(diagnostics.begin(), diagnostics.end(),
                   [](const Diagnostic& a, const Diagnostic& b) {
                     const bool aOutside = a.line == 0, bOutside = b.line == 0;
                     if (aOutside != bOutside) return bOutside;
                     if (aOutside) return false;
                     if (a.line != b.line) return a.line < b.line;
                     return a.column < b.column;
                   });
}

std::string formatNumber(double value) {
  if (std::isnan(value)) return "nan";
  if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
  if (value == std::trunc(value) && std::abs(value) < 1e15) {
    return std::to_string(static_cast<long long>(value));
  }
  char buffer[64];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  return std::string(buffer, result.ptr);
}

}  // namespace tickfx::io

#include "particles/SettingProblem.h"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

namespace tickfx {

std::string SettingProblem::text() const {
  std::string out = key;
  out.append(": ").append(message).append(" (expected ").append(expected).append(")");
  return out;
}

void throwIfAny(std::string_view owner, const SettingProblems& problems) {
  if (problems.empty()) return;
  throw std::invalid_argument(std::string(owner) + " " + problems.front().text());
}

void checkFinite(const Eigen::Vector3d& v, const std::string& key, SettingProblems& out) {
  if (!v.allFinite()) out.push_back({key, "is not finite", "three finite numbers"});
}

std::string settingNumber(double value) {
  if (std::isnan(value)) return "nan";
  if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
  char buffer[64];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  return std::string(buffer, result.ptr);
}

template <typename T>
bool normalisable(const Eigen::Matrix<T, 3, 1>& v) {
  const T squared = v.squaredNorm();
  return v.allFinite() && std::isfinite(squared) && squared >= std::numeric_limits<T>::min();
}

template <typename T>
std::string shortestNormalisable() {
  // √min rounded up to two digits, so that a vector of the length shown passes.
  const double shortest = std::sqrt(static_cast<double>(std::numeric_limits<T>::min()));
  const double unit = std::pow(10.0, std::floor(std::log10(shortest)) - 1.0);
  char figure[32];
  std::snprintf(figure, sizeof figure, "%.2g", std::ceil(shortest / unit) * unit);
  return figure;
}

template <typename T>
void checkDirection(const Eigen::Matrix<T, 3, 1>& v, const std::string& key, SettingProblems& out) {
  if (normalisable(v)) return;
  const std::string precision = sizeof(T) == sizeof(double) ? "double" : "float";
  if (!v.allFinite()) {
    out.push_back({key, "is not finite", "a direction [x, y, z] of finite numbers"});
  } else if (!std::isfinite(v.squaredNorm())) {
    char figure[32];
    std::snprintf(figure, sizeof figure, "%.2g",
                  std::sqrt(static_cast<double>(std::numeric_limits<T>::max())) * 0.99);
    out.push_back({key, "is too long to normalise in " + precision + " precision",
                   "a direction [x, y, z] at most " + std::string(figure) + " long"});
  } else {
    out.push_back({key, "is too short to normalise in " + precision + " precision",
                   "a direction [x, y, z] at least " + shortestNormalisable<T>() + " long"});
  }
}

template bool normalisable<float>(const Eigen::Matrix<float, 3, 1>&);
template bool normalisable<double>(const Eigen::Matrix<double, 3, 1>&);
template std::string shortestNormalisable<float>();
template std::string shortestNormalisable<double>();
template void checkDirection<float>(const Eigen::Matrix<float, 3, 1>&, const std::string&,
                                    SettingProblems&);
template void checkDirection<double>(const Eigen::Matrix<double, 3, 1>&, const std::string&,
                                     SettingProblems&);

}  // namespace tickfx

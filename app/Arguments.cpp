#include "app/Arguments.h"

#include <charconv>
#include <cmath>
#include <cstdlib>
#include <sstream>

namespace tickfx::app {

bool Arguments::flag(const std::string& name) {
  bool found = false;
  for (auto it = args_.begin(); it != args_.end();) {
    if (*it == name) {
      found = true;
      it = args_.erase(it);
    } else {
      ++it;
    }
  }
  return found;
}

std::vector<std::string> Arguments::values(const std::string& name) {
  std::vector<std::string> found;
  for (auto it = args_.begin(); it != args_.end();) {
    if (*it == name) {
      if (it + 1 == args_.end()) throw UsageError(command_ + ": " + name + " needs a value");
      found.push_back(*(it + 1));
      it = args_.erase(it, it + 2);
    } else if (it->rfind(name + "=", 0) == 0) {
      found.push_back(it->substr(name.size() + 1));
      it = args_.erase(it);
    } else {
      ++it;
    }
  }
  return found;
}

std::optional<std::string> Arguments::value(const std::string& name) {
  std::vector<std::string> found = values(name);
  if (found.empty()) return std::nullopt;
  return found.back();
}

std::vector<std::string> Arguments::positionals(std::size_t count, const std::string& what) {
  for (const std::string& a : args_) {
    if (a.size() > 1 && a[0] == '-')
      throw UsageError(command_ + ": unknown option '" + a + "' (see tickfx " + command_ +
                       " --help)");
  }
  if (args_.size() != count) {
    throw UsageError(command_ + ": expected " + what +
                     (args_.size() > count ? ", got extra arguments" : ""));
  }
  return args_;
}

std::vector<std::string> Arguments::positionalList(const std::string& what) {
  if (args_.empty()) throw UsageError(command_ + ": expected " + what);
  return positionals(args_.size(), what);
}

long long parseInteger(const std::string& text, const std::string& option, long long min,
                       long long max) {
  long long value = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || end != text.data() + text.size() || value < min || value > max) {
    throw UsageError(option + ": '" + text + "' is not a whole number in [" + std::to_string(min) +
                     ", " + std::to_string(max) + "]");
  }
  return value;
}

std::pair<long long, long long> parseRange(const std::string& text, long long min, long long max,
                                           const UsageError& refusal) {
  const std::size_t dots = text.find("..");
  if (dots == std::string::npos) throw refusal;
  try {
    const long long a = parseInteger(text.substr(0, dots), "", min, max);
    return {a, parseInteger(text.substr(dots + 2), "", a, max)};
  } catch (const UsageError&) {
    throw refusal;
  }
}

std::vector<double> parseNumberList(const std::string& text, const std::string& option,
                                    std::size_t count, const std::string& shape, double min,
                                    double max) {
  std::vector<std::string> parts;
  std::stringstream list(text);
  std::string part;
  while (std::getline(list, part, ',')) parts.push_back(part);
  if (!text.empty() && text.back() == ',') parts.push_back("");
  if (parts.size() != count) {
    throw UsageError(option + ": '" + text + "' is not " + std::to_string(count) + " numbers " +
                     shape);
  }
  std::vector<double> values;
  for (const std::string& p : parts) values.push_back(parseNumber(p, option, min, max));
  return values;
}

double parseNumber(const std::string& text, const std::string& option, double min, double max) {
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0' || !std::isfinite(value) || value < min || value > max) {
    char range[96];
    std::snprintf(range, sizeof range, "[%g, %g]", min, max);
    throw UsageError(option + ": '" + text + "' is not a number in " + range);
  }
  return value;
}

std::string joinWords(const std::vector<std::string>& words, const std::string& last) {
  std::string out;
  for (std::size_t i = 0; i < words.size(); ++i) {
    out += (i == 0 ? "" : (i + 1 == words.size() ? last : ", ")) + words[i];
  }
  return out;
}

}  // namespace tickfx::app

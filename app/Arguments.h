// A small, strict command-line reader: every argument must be consumed, or it is an error.
#pragma once

#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace tickfx::app {

/// A mistake in how the command was called (exit code 2).
class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The arguments after the subcommand. Options are taken by name (`--out DIR` or `--out=DIR`);
/// what is left must be the expected positionals, and anything unrecognised is a UsageError.
class Arguments {
 public:
  Arguments(std::string command, std::vector<std::string> args)
      : command_(std::move(command)), args_(std::move(args)) {}

  /// True (and consumed) when `--name` is present, as a switch.
  bool flag(const std::string& name);
  /// The value of the last `--name VALUE`, consumed; nothing when absent.
  std::optional<std::string> value(const std::string& name);
  /// Every value of a repeated `--name VALUE`, in order, consumed.
  std::vector<std::string> values(const std::string& name);
  /// The remaining arguments, which must not look like options; exactly `count` of them.
  std::vector<std::string> positionals(std::size_t count, const std::string& what);
  /// The remaining arguments, which must not look like options; at least one of them.
  std::vector<std::string> positionalList(const std::string& what);

  const std::string& command() const { return command_; }

 private:
  std::string command_;
  std::vector<std::string> args_;
};

/// Parses a whole number in [min, max]; UsageError naming `option` otherwise.
long long parseInteger(const std::string& text, const std::string& option, long long min,
                       long long max);
/// Parses a finite number in [min, max]; UsageError naming `option` otherwise.
double parseNumber(const std::string& text, const std::string& option, double min, double max);

/// Parses "A..B", whole numbers with min <= A <= B <= max; throws `refusal` otherwise.
std::pair<long long, long long> parseRange(const std::string& text, long long min, long long max,
                                           const UsageError& refusal);
/// Parses `count` comma-separated numbers, each finite and in [min, max]. UsageError "OPTION:
/// 'TEXT' is not COUNT numbers SHAPE" for another count, parseNumber's message for a bad number.
std::vector<double> parseNumberList(const std::string& text, const std::string& option,
                                    std::size_t count, const std::string& shape, double min,
                                    double max);

/// "a, b or c" with `last` = " or ": the words of a usage message's list of choices.
std::string joinWords(const std::vector<std::string>& words, const std::string& last);

}  // namespace tickfx::app

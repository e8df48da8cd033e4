// SPDX-License-Identifier: GPL-3.0-or-later
// Reading the subcommands' option values, with the messages every subcommand gives.
#pragma once

#include <cmath>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "commands.hpp"

namespace mpeg4face::cli {

// The value after the option args[i]; moves i onto it. `what` names it when it is missing
// ("-o needs an output file").
inline const std::string& optionValue(const std::vector<std::string>& args, size_t& i,
                                      const std::string& what) {
  if (i + 1 >= args.size()) throw UsageError(args[i] + " needs " + what);
  return args[++i];
}

// The whole text as a finite number, or nothing ("1.5x", "nan" and "" are not numbers).
inline std::optional<double> parseNumber(const std::string& text) {
  size_t used = 0;
  double value = 0;
  try {
    value = std::stod(text, &used);
  } catch (const std::exception&) {
    return std::nullopt;
  }
  if (used != text.size() || !std::isfinite(value)) return std::nullopt;
  return value;
}

// The whole text as an int, or nothing.
inline std::optional<int> parseInt(const std::string& text) {
  size_t used = 0;
  int value = 0;
  try {
    value = std::stoi(text, &used);
  } catch (const std::exception&) {
    return std::nullopt;
  }
  if (used != text.size()) return std::nullopt;
  return value;
}

// The value after option args[i] as a number >= min: "--threshold takes a number >= 0, not 'x'".
inline double numberArgument(const std::vector<std::string>& args, size_t& i,
                             const std::string& what, double min) {
  const std::string& option = args[i];
  const std::string& text = optionValue(args, i, what);
  const std::optional<double> value = parseNumber(text);
  if (!value || *value < min) {
    char bound[32];
    std::snprintf(bound, sizeof bound, "%g", min);
    throw UsageError(option + " takes a number >= " + bound + ", not '" + text + "'");
  }
  return *value;
}

// The value after option args[i] as a whole number in min..max.
inline int intArgument(const std::vector<std::string>& args, size_t& i, int min, int max) {
  const std::string& option = args[i];
  const std::string& text = optionValue(args, i, "a number");
  const std::optional<int> value = parseInt(text);
  if (!value || *value < min || *value > max) {
    throw UsageError(option + " takes a whole number in " + std::to_string(min) + ".." +
                     std::to_string(max) + ", not '" + text + "'");
  }
  return *value;
}

}  // namespace mpeg4face::cli

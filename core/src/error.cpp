// SPDX-License-Identifier: GPL-3.0-or-later
#include "mpeg4face/error.hpp"

namespace mpeg4face {
namespace {

std::string format(const std::string& file, int line, const std::string& field,
                   const std::string& message) {
  std::string out;
  if (!file.empty()) {
    out.append(file);
    if (line > 0) out.append(":").append(std::to_string(line));
    out.append(": ");
  }
  if (!field.empty()) out.append(field).append(": ");
  return out.append(message);
}

}  // namespace

Error::Error(std::string file, int line, std::string field, const std::string& message)
    : std::runtime_error(format(file, line, field, message)),
      file_(std::move(file)),
      line_(line),
      field_(std::move(field)),
      reason_(message) {}

}  // namespace mpeg4face

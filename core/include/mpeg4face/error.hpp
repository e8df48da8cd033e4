// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

#include <stdexcept>
#include <string>

namespace mpeg4face {

// The one exception type of the library. It names where the problem is (file, line, field)
// so that a user can find it; any of the three may be empty / 0 when not applicable.
class Error : public std::runtime_error {
 public:
  Error(std::string file, int line, std::string field, const std::string& message);
  explicit Error(const std::string& message) : Error({}, 0, {}, message) {}

  const std::string& file() const noexcept { return file_; }
  int line() const noexcept { return line_; }
  const std::string& field() const noexcept { return field_; }
  // The message without the "file:line: field:" prefix.
  const std::string& reason() const noexcept { return reason_; }

 private:
  std::string file_;
  int line_;
  std::string field_;
  std::string reason_;
};

}  // namespace mpeg4face

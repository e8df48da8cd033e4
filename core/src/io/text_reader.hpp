// SPDX-License-Identifier: GPL-3.0-or-later
// Internal: the small line reader shared by the text parsers (OBJ, CANDIDE .wfm, feature-point
// CSV), so that line numbering, tokenising, strict number parsing and error messages behave
// the same in all of them. Not installed; not part of the public API.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace mpeg4face::text {

// Space, tab, \v, \f and a stray \r (the line ending itself is removed by LineReader).
constexpr bool isSpace(char c) {
  return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
}
std::string_view trim(std::string_view s);
// Splits `line` on runs of whitespace into `tokens` (cleared first). Reusing one vector across
// lines keeps a parser's inner loop free of allocations.
void splitWhitespace(std::string_view line, std::vector<std::string_view>& tokens);
// `token` as a message shows it: in quotes, bytes outside printable ASCII as \xNN (binary input
// must still give a readable message), cut after 40 bytes.
std::string quote(std::string_view token);
// Names from old files may be Latin-1 (CANDIDE's comments are); downstream writers (glTF JSON)
// need UTF-8. Returns `s` unchanged if it is valid UTF-8, else reads it as Latin-1.
std::string toUtf8(std::string_view s);

// Strict numbers: the whole token must be the number (std::from_chars, so "1x", "" and " 1"
// fail), finite, in range; a leading '+' is accepted. The try- forms return false on failure,
// the others throw Error(file, line, field, "integer expected, found '<token>'") and the like.
bool tryParseInt(std::string_view token, int& value);
bool tryParseDouble(std::string_view token, double& value);
int parseInt(std::string_view token, const std::string& file, int line, std::string_view field);
double parseDouble(std::string_view token, const std::string& file, int line,
                   std::string_view field);

// Iterates the lines of a text with 1-based numbers. Line endings \n and \r\n; the last line
// counts whether or not it ends with one; a UTF-8 byte-order mark at the start is skipped.
class LineReader {
 public:
  LineReader(std::string_view text, std::string fileName);

  // The next line without its line ending; false at the end of the text.
  bool next(std::string_view& line);
  // Number of the line `next` returned last (0 before the first call).
  int lineNumber() const { return line_; }
  const std::string& fileName() const { return file_; }
  // Bytes not yet returned: an upper bound for what the rest of the file can hold, used to cap
  // reserve() calls driven by counts in the input.
  std::size_t remainingBytes() const { return text_.size() - pos_; }

  // Throws Error(fileName, lineNumber(), field, message).
  [[noreturn]] void fail(std::string_view field, const std::string& message) const;
  int toInt(std::string_view token, std::string_view field) const {
    return parseInt(token, file_, line_, field);
  }
  double toDouble(std::string_view token, std::string_view field) const {
    return parseDouble(token, file_, line_, field);
  }

 private:
  std::string_view text_;
  std::string file_;
  std::size_t pos_ = 0;
  int line_ = 0;
};

}  // namespace mpeg4face::text

// SPDX-License-Identifier: GPL-3.0-or-later
#include "io/text_reader.hpp"

#include <charconv>
#include <cmath>
#include <system_error>
#include <type_traits>
#include <utility>

#include "mpeg4face/error.hpp"

namespace mpeg4face::text {
namespace {

// from_chars rejects '+', which hand-written files occasionally use.
std::string_view withoutPlus(std::string_view token) {
  if (token.size() > 1 && token[0] == '+' && token[1] != '-' && token[1] != '+') {
    token.remove_prefix(1);
  }
  return token;
}

enum class Parsed { Ok, Invalid, OutOfRange };

template <typename T>
Parsed parseStrict(std::string_view token, T& value) {
  const std::string_view digits = withoutPlus(token);
  const char* last = digits.data() + digits.size();
  const auto [end, ec] = std::from_chars(digits.data(), last, value);
  if (ec == std::errc::result_out_of_range) return Parsed::OutOfRange;
  if (ec != std::errc() || end != last) return Parsed::Invalid;
  if constexpr (std::is_floating_point_v<T>) {
    if (!std::isfinite(value)) return Parsed::Invalid;  // from_chars accepts "nan" and "inf"
  }
  return Parsed::Ok;
}

template <typename T>
T parseOrThrow(std::string_view token, const std::string& file, int line, std::string_view field,
               const char* what) {
  T value{};
  switch (parseStrict(token, value)) {
    case Parsed::Ok:
      return value;
    case Parsed::OutOfRange:
      throw Error(file, line, std::string(field),
                  std::string(what) + " out of range: " + quote(token));
    case Parsed::Invalid:
      break;
  }
  throw Error(file, line, std::string(field),
              std::string(what) + " expected, found " + (token.empty() ? "nothing" : quote(token)));
}

}  // namespace

std::string_view trim(std::string_view s) {
  while (!s.empty() && isSpace(s.front())) s.remove_prefix(1);
  while (!s.empty() && isSpace(s.back())) s.remove_suffix(1);
  return s;
}

void splitWhitespace(std::string_view line, std::vector<std::string_view>& tokens) {
  tokens.clear();
  std::size_t i = 0;
  const std::size_t n = line.size();
  while (true) {
    while (i < n && isSpace(line[i])) ++i;
    if (i == n) return;
    const std::size_t begin = i;
    while (i < n && !isSpace(line[i])) ++i;
    tokens.push_back(line.substr(begin, i - begin));
  }
}

std::string quote(std::string_view token) {
  constexpr std::size_t kMaxShown = 40;
  static constexpr char kHex[] = "0123456789abcdef";
  std::string out = "'";
  for (std::size_t i = 0; i < token.size() && i < kMaxShown; ++i) {
    const auto c = static_cast<unsigned char>(token[i]);
    if (c >= 0x20 && c < 0x7f) {
      out += static_cast<char>(c);
    } else {
      out += "\\x";
      out += kHex[c >> 4];
      out += kHex[c & 0xf];
    }
  }
  out += token.size() > kMaxShown ? "'..." : "'";
  return out;
}

std::string toUtf8(std::string_view s) {
  // Validate as UTF-8 (RFC 3629: no overlongs, no surrogates, at most U+10FFFF).
  bool valid = true;
  for (std::size_t i = 0; i < s.size() && valid;) {
    const auto c = static_cast<unsigned char>(s[i]);
    int extra = 0;
    unsigned lo = 0x80, hi = 0xbf;  // allowed range of the second byte
    if (c < 0x80) {
      ++i;
      continue;
    } else if (c >= 0xc2 && c <= 0xdf) {
      extra = 1;
    } else if (c >= 0xe0 && c <= 0xef) {
      extra = 2;
      if (c == 0xe0) lo = 0xa0;
      if (c == 0xed) hi = 0x9f;
    } else if (c >= 0xf0 && c <= 0xf4) {
      extra = 3;
      if (c == 0xf0) lo = 0x90;
      if (c == 0xf4) hi = 0x8f;
    } else {
      valid = false;
      break;
    }
    if (i + extra >= s.size()) {
      valid = false;
      break;
    }
    for (int k = 1; k <= extra; ++k) {
      const auto b = static_cast<unsigned char>(s[i + k]);
      if (k == 1 ? (b < lo || b > hi) : (b < 0x80 || b > 0xbf)) valid = false;
    }
    i += extra + 1;
  }
  if (valid) return std::string(s);
  std::string out;
  out.reserve(s.size() * 2);
  for (char ch : s) {
    const auto c = static_cast<unsigned char>(ch);
    if (c < 0x80) {
      out += ch;
    } else {
      out += static_cast<char>(0xc0 | (c >> 6));
      out += static_cast<char>(0x80 | (c & 0x3f));
    }
  }
  return out;
}

bool tryParseInt(std::string_view token, int& value) {
  return parseStrict(token, value) == Parsed::Ok;
}

bool tryParseDouble(std::string_view token, double& value) {
  return parseStrict(token, value) == Parsed::Ok;
}

int parseInt(std::string_view token, const std::string& file, int line, std::string_view field) {
  return parseOrThrow<int>(token, file, line, field, "integer");
}

double parseDouble(std::string_view token, const std::string& file, int line,
                   std::string_view field) {
  return parseOrThrow<double>(token, file, line, field, "finite number");
}

LineReader::LineReader(std::string_view text, std::string fileName)
    : text_(text), file_(std::move(fileName)) {
  if (text_.substr(0, 3) == "\xEF\xBB\xBF") pos_ = 3;
}

bool LineReader::next(std::string_view& line) {
  if (pos_ >= text_.size()) return false;
  std::size_t end = text_.find('\n', pos_);
  const bool lastLine = end == std::string_view::npos;
  if (lastLine) end = text_.size();
  line = text_.substr(pos_, end - pos_);
  if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
  pos_ = lastLine ? end : end + 1;
  ++line_;
  return true;
}

void LineReader::fail(std::string_view field, const std::string& message) const {
  throw Error(file_, line_, std::string(field), message);
}

}  // namespace mpeg4face::text

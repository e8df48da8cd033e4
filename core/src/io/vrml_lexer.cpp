// SPDX-License-Identifier: GPL-3.0-or-later
// VRML97 reader: the lexer over the whole text, and the text a string token or a DEF name
// stands for.
#include <algorithm>

#include "io/text_reader.hpp"
#include "io/vrml_names.hpp"
#include "io/vrml_reader.hpp"

namespace mpeg4face::vrml_reader {

namespace names = vrml_names;

namespace {

// VRML97 identifiers (ISO/IEC 14772-1 annex A): no control characters, space, " # ' , . [ \ ]
// { } or DEL; the first character also not a digit, + or -.
bool idRestChar(unsigned char c) {
  if (c <= 0x20 || c == 0x7f) return false;
  switch (c) {
    case '"':
    case '#':
    case '\'':
    case ',':
    case '.':
    case '[':
    case '\\':
    case ']':
    case '{':
    case '}':
      return false;
    default:
      return true;
  }
}
bool idFirstChar(unsigned char c) {
  return idRestChar(c) && !(c >= '0' && c <= '9') && c != '+' && c != '-';
}
bool isDigit(char c) { return c >= '0' && c <= '9'; }

}  // namespace

std::string describe(const Token& t) {
  switch (t.kind) {
    case Tok::End:
      return "the end of the file";
    case Tok::String:
      return "a string";
    default:
      return text::quote(t.text);
  }
}

Token Lexer::scan() {
  // Whitespace (commas included, as VRML97 says) and comments.
  while (pos_ < text_.size()) {
    const char c = text_[pos_];
    if (c == '\n') {
      ++line_;
      ++pos_;
    } else if (c == ' ' || c == '\t' || c == '\r' || c == ',' || c == '\f' || c == '\v') {
      ++pos_;
    } else if (c == '#') {
      while (pos_ < text_.size() && text_[pos_] != '\n') ++pos_;
    } else {
      break;
    }
  }
  Token t;
  t.line = line_;
  if (pos_ >= text_.size()) {
    t.line = lastLine_;  // "found the end of the file" on the last line, not after it
    return t;
  }
  lastLine_ = line_;
  const std::size_t begin = pos_;
  const auto c = static_cast<unsigned char>(text_[pos_]);
  const auto punct = [&](Tok kind) {
    t.kind = kind;
    t.text = text_.substr(pos_++, 1);
    return t;
  };
  switch (c) {
    case '{':
      return punct(Tok::LBrace);
    case '}':
      return punct(Tok::RBrace);
    case '[':
      return punct(Tok::LBracket);
    case ']':
      return punct(Tok::RBracket);
    default:
      break;
  }
  if (c == '"') {
    ++pos_;
    while (pos_ < text_.size() && text_[pos_] != '"') {
      if (text_[pos_] == '\\' && pos_ + 1 < text_.size()) ++pos_;
      if (text_[pos_] == '\n') ++line_;
      ++pos_;
    }
    if (pos_ >= text_.size()) fail(t.line, {}, "string not closed (it opens on this line)");
    t.kind = Tok::String;
    t.text = text_.substr(begin + 1, pos_ - begin - 1);
    ++pos_;
    return t;
  }
  if (c == '.' && !(pos_ + 1 < text_.size() && isDigit(text_[pos_ + 1]))) return punct(Tok::Period);
  if (isDigit(static_cast<char>(c)) || c == '+' || c == '-' || c == '.') {
    // Everything up to the next separator; the parser checks the number (a stray letter
    // in "1.5x" is an error there, with the field's name).
    while (pos_ < text_.size() && idRestChar(static_cast<unsigned char>(text_[pos_]))) ++pos_;
    while (pos_ < text_.size() && text_[pos_] == '.') {  // '.' ends identifiers, not numbers
      ++pos_;
      while (pos_ < text_.size() && idRestChar(static_cast<unsigned char>(text_[pos_]))) ++pos_;
    }
    t.kind = Tok::Number;
    t.text = text_.substr(begin, pos_ - begin);
    return t;
  }
  if (idFirstChar(c)) {
    while (pos_ < text_.size() && idRestChar(static_cast<unsigned char>(text_[pos_]))) ++pos_;
    t.kind = Tok::Id;
    t.text = text_.substr(begin, pos_ - begin);
    return t;
  }
  fail(t.line, {}, "unexpected character " + text::quote(text_.substr(pos_, 1)));
}

std::string unescape(std::string_view s) {
  std::string out;
  out.reserve(s.size());
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s[i] == '\\' && i + 1 < s.size()) ++i;
    out += s[i];
  }
  return out;
}

namespace {

int hexValue(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

}  // namespace

std::string nameFromDef(std::string_view def) {
  const std::size_t suffix = def.rfind(names::kUniqueSuffix);
  if (suffix != std::string_view::npos) {
    const std::string_view digits = def.substr(suffix + names::kUniqueSuffix.size());
    if (!digits.empty() && std::all_of(digits.begin(), digits.end(), isDigit)) {
      def = def.substr(0, suffix);
    }
  }
  std::string out;
  for (std::size_t i = 0; i < def.size(); ++i) {
    if (def[i] == names::kEscape && i + 2 < def.size() && hexValue(def[i + 1]) >= 0 &&
        hexValue(def[i + 2]) >= 0) {
      out += static_cast<char>(hexValue(def[i + 1]) * 16 + hexValue(def[i + 2]));
      i += 2;
    } else {
      out += def[i];
    }
  }
  return out;
}

}  // namespace mpeg4face::vrml_reader
